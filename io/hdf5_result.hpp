#pragma once
/// OUT/result.h5: the model, the final state and optional frames of a run, plus the scene text.
/// Layout (dataset names, shapes, units) is documented in docs/OUTPUTS.md.
#include <string>

#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/run_result.hpp"

namespace vb {

/// Writes `path` atomically (temporary file, closed, then renamed). Array sizes in `state` and
/// `frames` must match the lattice's element count. Throws vb::Error naming the failing dataset.
void write_result_h5(const std::string& path, const Lattice& lattice, const Scene& scene,
                     const FinalState& state, const Frames& frames, const RunSummary& summary);

}  // namespace vb
