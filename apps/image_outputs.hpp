#pragma once
/// Results of an image model on the input CT's grid: DVFs, warped CT (NIfTI + DICOM), the
/// model's labels and per-element fields.
#include <nlohmann/json.hpp>
#include <string>

#include "engine/image/image_volume.hpp"
#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/run_result.hpp"

namespace vb::app {

/// Writes the outputs the scene asks for into `dir`; returns what was written (for summary.json).
nlohmann::json write_image_outputs(const std::string& dir, const Scene& scene, const Lattice& lattice,
                                   const ImageVolume& ct, const FinalState& state);

}  // namespace vb::app
