#pragma once
/// Surface meshes and the volume lattice for viewers (ParaView, 3D Slicer), written when the
/// scene sets output.surfaces (docs/OUTPUTS.md, "Meshes").
#include <nlohmann/json.hpp>
#include <string>

#include "engine/lattice/lattice.hpp"
#include "engine/sim/run_result.hpp"

namespace vb::app {

/// Writes surface_rest.vtp, surface.vtp, surface.stl, surface.ply and lattice.vtu into `dir` (and
/// surface_unloaded.vtp with an unloaded reference state), and
/// with displacement frames ParaView time series: frames/surface_NNNN.vtp, frames/lattice_NNNN.vtu,
/// surface.pvd and lattice.pvd;
/// returns what was written and the mesh counts (for summary.json).
nlohmann::json write_mesh_outputs(const std::string& dir, const Lattice& lattice, const FinalState& state,
                                  const Frames& frames);

}  // namespace vb::app
