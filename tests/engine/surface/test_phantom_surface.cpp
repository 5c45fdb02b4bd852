// The surface of the bundled phantoms: counts, timing (< 1 s for a 36k-element model on one
// core) and the enclosed volume against the voxel volume (docs/SURFACE.md, "Numbers").
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <iostream>

#include "engine/image/image_lattice.hpp"
#include "engine/lattice/dual_cells.hpp"
#include "engine/lattice/voxelise.hpp"
#include "engine/surface/enclosed_volume.hpp"
#include "engine/surface/surface_elements.hpp"
#include "engine/surface/surface_mesh.hpp"
#include "io/nifti_io.hpp"
#include "io/scene_file.hpp"
#include "tests/engine/surface/mesh_checks.hpp"

namespace vb {
namespace {

const std::string kSamples = std::string(VOXBREAST_SOURCE_DIR) + "/data-samples/";

/// The phantom CT's lattice, as `voxbreast simulate data-samples/phantom/scene.toml` builds it
/// (spacing 0 keeps the scene's). The CT and labels are read once.
Lattice phantom_ct_lattice(double spacing_m = 0, std::vector<std::string> keep = {}) {
  Scene scene = parse_scene_file(kSamples + "phantom/scene.toml");
  if (spacing_m > 0) scene.model.spacing_m = spacing_m;
  if (!keep.empty()) scene.model.keep = keep;
  static const ImageVolume ct = read_nifti(scene.model.image_path);
  static const ImageVolume labels = read_nifti(scene.model.labels_path);
  const TissueMap map = classify_image(scene.model, ct, &labels);
  return build_lattice(lattice_volume_from_image(scene.model, ct, map), scene.model.downsample);
}

Lattice analytic_phantom_lattice(double spacing_m = 0) {
  Scene scene = parse_scene_file(kSamples + "breast_phantom.toml");
  if (spacing_m > 0) scene.model.spacing_m = spacing_m;
  return build_lattice(voxelise_shapes(scene), scene.model.downsample);
}

/// Fastest of 3 builds (s): the machine is shared, the minimum is the cost.
double build_seconds(const Lattice& lattice, SurfaceMesh& mesh) {
  double best = 1e9;
  for (int run = 0; run < 3; ++run) {
    const auto t0 = std::chrono::steady_clock::now();
    mesh = build_surface(lattice);
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

double mesh_area_m2(const SurfaceMesh& mesh, const std::vector<double>& x) {
  double area = 0;
  auto p = [&](std::uint32_t v) {
    const std::size_t e = mesh.element_of_vertex[v];
    return Eigen::Vector3d(x[3 * e], x[3 * e + 1], x[3 * e + 2]);
  };
  for (const auto& t : mesh.triangles) area += 0.5 * (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).norm();
  return area;
}

void report_and_check(const std::string& name, const Lattice& lat, bool check_intersections) {
  SurfaceMesh mesh;
  const double seconds = build_seconds(lat, mesh);
  const test::MeshTopology topo = test::check_topology(mesh);
  EXPECT_TRUE(topo.problems.empty()) << name << ": " << topo.describe();
  if (check_intersections) EXPECT_EQ(test::count_rest_intersections(lat, mesh), 0u) << name;

  const double h3 = std::pow(lat.spacing_m, 3);
  const std::vector<double> x = element_positions_m(lat);
  const double volume = enclosed_volume_m3(mesh, x);
  const double voxel_volume = double(lat.element_count()) * h3;
  const double area = mesh_area_m2(mesh, x);
  EXPECT_NEAR(volume / h3, double(mesh.complete_cell_count), 1e-9 * double(mesh.complete_cell_count)) << name;
  // The missing shell: Σ(1 − w_e)·h³ exactly, ≈ area·h/2 (convex edges and corners add to it,
  // concave ones take away).
  const double shell_estimate = area * lat.spacing_m / 2;
  EXPECT_GT(voxel_volume - volume, 0.9 * shell_estimate) << name;
  EXPECT_LT(voxel_volume - volume, 1.2 * shell_estimate) << name;

  std::cout << name << ": " << lat.element_count() << " elements (h = " << lat.spacing_m * 1e3
            << " mm), " << mesh.surface_element_count << " surface elements, " << mesh.vertex_count()
            << " vertices, " << mesh.triangles.size() << " triangles, " << topo.components
            << " component(s), genus " << topo.genus << ", " << mesh.split_element_count
            << " split elements, " << mesh.empty_paired_edge_count << " empty-paired edges, "
            << mesh.outside_body_count << " elements outside the body; build " << seconds * 1e3
            << " ms\n  volume: voxels " << voxel_volume * 1e6 << " cm³, enclosed " << volume * 1e6
            << " cm³ (" << 100 * (volume / voxel_volume - 1) << " %), difference "
            << (voxel_volume - volume) * 1e6 << " cm³ = " << (voxel_volume - volume) / shell_estimate
            << " × area·h/2 (area " << area * 1e4 << " cm²)\n";
  ::testing::Test::RecordProperty(name + "_elements", std::to_string(lat.element_count()));
  ::testing::Test::RecordProperty(name + "_surface_elements", std::to_string(mesh.surface_element_count));
  ::testing::Test::RecordProperty(name + "_triangles", std::to_string(mesh.triangles.size()));
  ::testing::Test::RecordProperty(name + "_build_ms", std::to_string(seconds * 1e3));
}

TEST(PhantomSurface, PhantomCtAtSceneSpacing) { report_and_check("phantom_ct", phantom_ct_lattice(), true); }

TEST(PhantomSurface, PhantomCtBreastTissuesOnly) {
  // Without the chest-wall muscle (whose tunnels give the full model its genus).
  report_and_check("phantom_ct_breast_only", phantom_ct_lattice(0, {"skin", "adipose", "fibroglandular", "tumour"}), true);
}

TEST(PhantomSurface, AnalyticPhantomAtSceneSpacing) {
  report_and_check("analytic_phantom", analytic_phantom_lattice(), true);
}

TEST(PhantomSurface, ThirtySixThousandElementsUnderOneSecond) {
  // The paper's breast model size: the phantom CT at a finer lattice spacing (3.2 mm).
  const Lattice lat = phantom_ct_lattice(0.0032);
  EXPECT_GT(lat.element_count(), 34000u);
  report_and_check("phantom_ct_36k", lat, true);
}

}  // namespace
}  // namespace vb
