#pragma once
/// Meshes of the immobilisation device next to the breast surface, so both open together in
/// ParaView or 3D Slicer (docs/OUTPUTS.md, "Meshes"); written with output.surfaces.
#include <nlohmann/json.hpp>
#include <string>

#include "engine/scene/scene.hpp"
#include "engine/sim/run_result.hpp"

namespace vb::app {

/// Writes device_<torus>.vtp and device_<torus>.stl at the final time `t_s` for every torus and,
/// with displacement frames, frames/device_<torus>_NNNN.vtp and device_<torus>.pvd (the inflation
/// as a time series). Returns the files written (names relative to `dir`).
nlohmann::json write_device_meshes(const std::string& dir, const Scene& scene, double t_s, const Frames& frames);

}  // namespace vb::app
