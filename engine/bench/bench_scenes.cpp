#include "engine/bench/bench_scenes.hpp"

#include <cmath>
#include <filesystem>
#include <numbers>

#include "engine/error.hpp"
#include "engine/image/image_lattice.hpp"
#include "engine/lattice/voxelise.hpp"
#include "io/dicom_io.hpp"
#include "io/nifti_io.hpp"
#include "io/scene_file.hpp"

namespace vb::bench {

BenchScene column_scene(int nxy, int nz, double h) {
  constexpr int base_layers = 4;  // one element thick at downsample 4
  const double E = 20000, rho = 1000, g = 9.80665;
  BenchScene b;
  b.name = "column";
  Scene& s = b.scene;
  ShapeSpec box;
  box.kind = ShapeSpec::Kind::Box;
  box.min_m = Vec3::Zero();
  box.max_m = h * Vec3(nxy, nxy, nz + base_layers);
  box.label = "soft";
  s.model.spacing_m = h;
  s.model.shapes.push_back(box);
  MaterialSpec m;
  m.name = "soft";
  m.youngs_modulus_pa = E;  // peak strain ρgL/E ≈ 2.5% at L = 5 cm: the closed form's regime
  m.density_kg_m3 = rho;
  s.materials["soft"] = m;
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -g);
  AnchorSpec base;
  base.name = "base";
  base.kind = AnchorSpec::Kind::HalfSpace;
  base.point_m = Vec3(0, 0, base_layers * h);
  base.normal = Vec3(0, 0, -1);
  s.anchors.push_back(base);
  const double length = nz * h;
  const double omega1 = std::numbers::pi / (2 * length) * std::sqrt(E / rho);  // first axial mode of the column
  s.solver.damping_per_s = 2 * omega1;
  s.solver.dashpot_ratio = 0.1;
  s.stop.equilibrium = 1e-5;
  s.stop.max_steps = 200000;
  TrackSpec top;
  top.name = "top_centre";
  top.point_m = Vec3(0.5 * nxy * h, 0.5 * nxy * h, (nz + base_layers - 0.5) * h);
  s.tracks.push_back(top);
  b.volume = voxelise_shapes(s);
  b.column = ColumnClosedForm{length, (nz + base_layers) * h, E, rho, g};
  return b;
}

BenchScene image_scene(const std::string& name, const std::string& scene_path, double spacing_m) {
  BenchScene b;
  b.name = name;
  b.scene = parse_scene_file(scene_path);
  ModelSpec& model = b.scene.model;
  require(model.from_image(), "the phantom scene '" + scene_path + "' is not a CT scene", "bench --phantom",
          "give the scene.toml that `voxbreast phantom` writes");
  if (spacing_m > 0) model.spacing_m = spacing_m;
  model.downsample = 1;  // the bench sets the resolution
  std::vector<std::string> warnings;
  const ImageVolume ct = std::filesystem::is_directory(model.image_path)
                             ? read_dicom_series(model.image_path, model.series_uid, model.allow_gaps, &warnings)
                             : read_nifti(model.image_path);
  std::optional<ImageVolume> labels;
  if (!model.labels_path.empty()) labels = read_nifti(model.labels_path);
  const TissueMap map = classify_image(model, ct, labels ? &*labels : nullptr);
  b.volume = lattice_volume_from_image(model, ct, map);
  b.scene.output = OutputSpec{};  // the bench writes no per-run files
  return b;
}

}  // namespace vb::bench
