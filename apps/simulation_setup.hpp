#pragma once
/// Scene → model steps shared by the subcommands.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "engine/image/image_volume.hpp"
#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/element_setup.hpp"
#include "engine/sim/opencl_runtime.hpp"

namespace vb::app {

/// Parses the scene; `precision` ("" keeps the scene's) overrides solver.precision.
Scene load_scene(const std::string& path, const std::string& precision);

struct PreparedModel {
  Lattice lattice;
  ElementArrays elements;
  std::optional<ImageVolume> ct;      ///< the input CT, for image models
  /// The CT's label map (model.labels, or model.structures rasterised), when the model has one,
  /// and each label value's name (the ROI's name for structures, else the tissue's).
  std::optional<ImageVolume> labels;
  std::map<int, std::string> label_names;
  std::vector<std::string> warnings;  ///< e.g. DICOM slice gaps accepted with allow_gaps
};

/// Reads a CT: a folder is a DICOM series, a file is NIfTI.
ImageVolume load_ct(const ModelSpec& model, std::vector<std::string>& warnings);

/// Builds the lattice from shapes or from the CT (+ labels) and the per-element arrays. With a
/// `device`, a lattice too large for it is refused before its arrays are built.
PreparedModel prepare_model(const Scene& scene, const DeviceInfo* device = nullptr);

}  // namespace vb::app
