#pragma once
/// Results of an image model on the input CT's grid: DVFs, warped CT (NIfTI + DICOM), the
/// model's labels and per-element fields. Each is computed on all the host's cores, written in
/// compressed blocks as it is converted, and dropped before the next: besides the CT, at most
/// the inverse DVF (3 floats a voxel) and the warped CT (1) are held at once.
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "apps/simulation_setup.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/run_result.hpp"

namespace vb::app {

/// Told what is being made (e.g. "inverse DVF") and the fraction of all the image outputs done.
using ImageOutputProgress = std::function<void(const std::string& what, double fraction)>;

/// Writes the outputs the scene asks for into `dir`; returns what was written (for summary.json),
/// with the peak host memory of the process while writing them (Linux).
/// With a label map (model.labels or model.structures), also the warped label map, and with the
/// warped CT series an RTSTRUCT of the warped labels referencing it.
nlohmann::json write_image_outputs(const std::string& dir, const Scene& scene, const PreparedModel& model,
                                   const FinalState& state, const ImageOutputProgress& progress = {});

}  // namespace vb::app
