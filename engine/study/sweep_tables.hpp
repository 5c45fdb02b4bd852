#pragma once
/// metrics.csv and timing.csv, rebuilt from the case folders (docs/SWEEP.md, "metrics.csv"):
/// one row per case in case order, so an interrupted and resumed sweep, a multi-device sweep and
/// an MPI sweep all write the same metrics.csv, byte for byte.
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "engine/study/sweep_folder.hpp"
#include "engine/study/sweep_grid.hpp"

namespace vb {

/// The scalar leaves of a JSON document as (dotted path, value): objects by key, arrays by
/// 1-based index (tracked.apex.displacement_m.3); numbers, booleans and nulls (non-finite
/// numbers) are kept, strings are left out (names, paths, versions).
std::vector<std::pair<std::string, nlohmann::json>> flatten_scalars(const nlohmann::json& document);

/// Fields that measure time spent (…wall_time_s, …per_second): they go to timing.csv, not
/// metrics.csv, because they differ from run to run.
bool is_timing_field(const std::string& path);

/// A scalar as CSV text: shortest round-trip numbers, true/false, "" for null.
std::string scalar_text(const nlohmann::json& value);

struct SweepTablesReport {
  std::size_t ok = 0, failed = 0, pending = 0;
};

/// Writes DIR/metrics.csv and DIR/timing.csv (atomically) from every case folder. Columns of
/// metrics.csv: case, the varied keys, status (ok | failed | pending), error, then every
/// metric of summary.json (flatten_scalars without timing fields), in order of first
/// appearance over the cases.
SweepTablesReport write_sweep_tables(const SweepFolder& folder, const SweepGrid& grid);

}  // namespace vb
