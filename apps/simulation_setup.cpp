#include "apps/simulation_setup.hpp"

#include <filesystem>

#include "engine/image/image_lattice.hpp"
#include "engine/lattice/voxelise.hpp"
#include "io/dicom_io.hpp"
#include "io/nifti_io.hpp"
#include "io/scene_file.hpp"

namespace vb::app {

Scene load_scene(const std::string& path, const std::string& precision) {
  Scene scene = parse_scene_file(path);
  if (precision == "double") scene.solver.precision = Precision::Double;
  if (precision == "float") scene.solver.precision = Precision::Float;
  return scene;
}

ImageVolume load_ct(const ModelSpec& model, std::vector<std::string>& warnings) {
  if (std::filesystem::is_directory(model.image_path))
    return read_dicom_series(model.image_path, model.series_uid, model.allow_gaps, &warnings);
  return read_nifti(model.image_path);
}

PreparedModel prepare_model(const Scene& scene) {
  PreparedModel m;
  if (scene.model.from_image()) {
    m.ct = load_ct(scene.model, m.warnings);
    std::optional<ImageVolume> labels;
    if (!scene.model.labels_path.empty()) labels = read_nifti(scene.model.labels_path);
    const TissueMap map = classify_image(scene.model, *m.ct, labels ? &*labels : nullptr);
    m.lattice = build_lattice(lattice_volume_from_image(scene.model, *m.ct, map), scene.model.downsample);
  } else {
    m.lattice = build_lattice(voxelise_shapes(scene), scene.model.downsample);
  }
  m.elements = make_element_arrays(scene, m.lattice);
  return m;
}

}  // namespace vb::app
