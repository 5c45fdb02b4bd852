#include "apps/simulation_setup.hpp"

#include "engine/lattice/voxelise.hpp"
#include "io/scene_file.hpp"

namespace vb::app {

Scene load_scene(const std::string& path, const std::string& precision) {
  Scene scene = parse_scene_file(path);
  if (precision == "double") scene.solver.precision = Precision::Double;
  if (precision == "float") scene.solver.precision = Precision::Float;
  return scene;
}

PreparedModel prepare_model(const Scene& scene) {
  PreparedModel m;
  m.lattice = build_lattice(voxelise_shapes(scene), scene.model.downsample);
  m.elements = make_element_arrays(scene, m.lattice);
  return m;
}

}  // namespace vb::app
