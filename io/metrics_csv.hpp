#pragma once
/// OUT/metrics.csv: one header line and one row of a run's positioning metrics, so a sweep can
/// gather cases into one table (columns in docs/OUTPUTS.md). Lengths in mm, forces in N,
/// pressures and stresses in Pa; a metric that does not apply (no tumour, no chest wall) is an
/// empty cell.
#include <string>
#include <utility>
#include <vector>

#include "engine/sim/run_result.hpp"
#include "engine/study/positioning_metrics.hpp"

namespace vb {

/// (column, value) pairs in column order; the same columns for every run of one scene.
std::vector<std::pair<std::string, std::string>> metrics_row(const RunSummary& summary,
                                                             const PositioningMetrics& metrics);

/// Writes the header and the row atomically; throws vb::Error.
void write_metrics_csv(const std::string& path, const RunSummary& summary, const PositioningMetrics& metrics);

}  // namespace vb
