#pragma once
/// Probing outputs (docs/OUTPUTS.md, "voxbreast probe"): probe_curves.csv (every equilibrium of
/// every press), probe_profile.csv (one row per press) and probe_summary.json. mm and N in files.
#include <string>

#include "engine/probe/press_line.hpp"

namespace vb {

/// Writes the three files into `dir` (atomically, each).
void write_probe_outputs(const std::string& dir, const Scene& scene, const ProbeResult& result);

}  // namespace vb
