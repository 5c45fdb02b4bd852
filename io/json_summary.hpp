#pragma once
/// OUT/summary.json: the run's key numbers for scripts and checks (layout in docs/OUTPUTS.md).
#include <nlohmann/json.hpp>
#include <string>

#include "engine/scene/scene.hpp"
#include "engine/sim/element_mass.hpp"
#include "engine/sim/reference_state.hpp"
#include "engine/sim/run_result.hpp"
#include "engine/study/positioning_metrics.hpp"

namespace vb {

/// Every field name carries its unit; non-finite numbers become null (JSON has no NaN).
nlohmann::json summary_to_json(const RunSummary& summary, const Scene& scene);

/// summary.json's `model`: the modelled body's mass and volume, in total and per tissue, beside
/// those of the union of the voxels and of the hull of the element centres (docs/OUTPUTS.md).
nlohmann::json model_mass_to_json(const Lattice& lattice, const std::vector<TissueMass>& tissues);

/// The `positioning` section of summary.json (docs/OUTPUTS.md); absent parts are null.
nlohmann::json positioning_to_json(const PositioningMetrics& metrics);

/// summary.json's `reference_state` (the unloaded state's estimate and its iterations).
nlohmann::json reference_state_to_json(const ReferenceState& state, const ReferenceStateSpec& spec);

/// The `positioning.reproducibility` section: the spreads with and without the device, each run.
nlohmann::json reproducibility_to_json(const ReproducibilityResult& result, const ReproducibilitySpec& spec);

/// Writes summary_to_json() to `path` atomically (temporary file + rename); throws vb::Error.
void write_summary_json(const std::string& path, const RunSummary& summary, const Scene& scene);

}  // namespace vb
