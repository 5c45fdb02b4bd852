// Surface of the elastic body (engine/surface/): topology, orientation, volume and its gradient on
// shapes that are not convex, thin, of genus 1, hollow or pinched (docs/SURFACE.md).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <set>

#include "engine/lattice/dual_cells.hpp"
#include "engine/surface/enclosed_volume.hpp"
#include "engine/surface/surface_elements.hpp"
#include "engine/surface/surface_mesh.hpp"
#include "tests/engine/surface/mesh_checks.hpp"

namespace vb {
namespace {

using Inside = std::function<bool(int, int, int)>;

struct ShapeCase {
  std::string name;
  std::array<int, 3> dims;
  Inside inside;
  std::size_t components;
  long genus;
};

std::ostream& operator<<(std::ostream& os, const ShapeCase& c) { return os << c.name; }

double sq(double x) { return x * x; }

/// Inside a box of elements [lo, hi] (inclusive voxel indices).
bool in_box(int i, int j, int k, std::array<int, 3> lo, std::array<int, 3> hi) {
  return i >= lo[0] && i <= hi[0] && j >= lo[1] && j <= hi[1] && k >= lo[2] && k <= hi[2];
}

const std::vector<ShapeCase>& shape_cases() {
  static const std::vector<ShapeCase> cases = {
      {"sphere", {16, 16, 16}, [](int i, int j, int k) { return sq(i - 7.6) + sq(j - 7.3) + sq(k - 7.8) <= sq(6.3); }, 1, 0},
      {"box", {7, 6, 8}, [](int i, int j, int k) { return in_box(i, j, k, {1, 1, 1}, {5, 4, 6}); }, 1, 0},
      {"concave_l", {10, 10, 6},
       [](int i, int j, int k) { return in_box(i, j, k, {1, 1, 1}, {8, 3, 4}) || in_box(i, j, k, {1, 1, 1}, {3, 8, 4}); }, 1, 0},
      {"slab_two_voxels_thick", {12, 11, 4}, [](int i, int j, int k) { return in_box(i, j, k, {1, 1, 1}, {10, 9, 2}); }, 1, 0},
      {"torus", {24, 24, 10},
       [](int i, int j, int k) {
         const double rho = std::hypot(i - 11.5, j - 11.5) - 7.0;
         return sq(rho) + sq(k - 4.5) <= sq(3.2);
       },
       1, 1},
      {"blobs_with_neck", {32, 14, 14},
       [](int i, int j, int k) {
         const bool a = sq(i - 7.0) + sq(j - 6.6) + sq(k - 6.4) <= 25.0;
         const bool b = sq(i - 23.0) + sq(j - 6.6) + sq(k - 6.4) <= 25.0;
         const bool neck = i >= 7 && i <= 23 && (j == 6 || j == 7) && (k == 6 || k == 7);  // 2×2 voxels
         return a || b || neck;
       },
       1, 0},
      {"hollow_sphere", {20, 20, 20},
       [](int i, int j, int k) {
         const double r2 = sq(i - 9.5) + sq(j - 9.4) + sq(k - 9.6);
         return r2 <= sq(8.4) && r2 > sq(4.2);
       },
       2, 0},
      // Cells [0,1]² and [2,3]² (in x, y) meet along the element column (2, 2, z): an edge pinch.
      {"edge_pinch", {6, 6, 5},
       [](int i, int j, int k) { return in_box(i, j, k, {0, 0, 0}, {2, 2, 4}) || in_box(i, j, k, {2, 2, 0}, {4, 4, 4}); }, 2, 0},
      {"corner_pinch", {5, 5, 5},
       [](int i, int j, int k) { return in_box(i, j, k, {0, 0, 0}, {2, 2, 2}) || in_box(i, j, k, {2, 2, 2}, {4, 4, 4}); }, 2, 0},
      // Two columns meeting along an edge pinch and joined by a roof: the pinch does not close a
      // loop (the parts are face-connected only), so the body is one sphere-like surface.
      {"pinch_under_a_roof", {6, 6, 8},
       [](int i, int j, int k) {
         return in_box(i, j, k, {0, 0, 0}, {2, 2, 7}) || in_box(i, j, k, {2, 2, 0}, {4, 4, 7}) ||
                in_box(i, j, k, {0, 0, 5}, {4, 4, 7});
       },
       1, 0},
      // Two one-element cavities whose empty cells meet along a single edge (from (3,3,2) to
      // (3,3,3)), while the solid around joins at both ends: the faces there pair around the empty
      // cells, so the cavities are separate surfaces.
      {"cavities_touching_along_one_edge", {7, 7, 7},
       [](int i, int j, int k) {
         return !((i == 2 && j == 4 && k == 3) || (i == 4 && j == 2 && k == 2));
       },
       3, 0},
      // The same along two edges: the middle element bounds two separate solid parts, so the
      // cavities join through the pinch (one surface).
      {"cavities_touching_along_two_edges", {7, 7, 7},
       [](int i, int j, int k) { return !((i == 2 && j == 2 && k == 3) || (i == 4 && j == 4 && k == 3)); }, 2, 0},
      {"cavities_touching_at_a_corner", {7, 7, 7},
       [](int i, int j, int k) { return !((i == 2 && j == 2 && k == 2) || (i == 4 && j == 4 && k == 4)); }, 3, 0},
      // A fin one voxel thick on a box: no complete cell, so no surface (and no volume).
      {"box_with_thin_fin", {10, 6, 6},
       [](int i, int j, int k) { return in_box(i, j, k, {0, 0, 0}, {3, 3, 3}) || in_box(i, j, k, {4, 1, 2}, {9, 4, 2}); },
       1, 0},
  };
  return cases;
}

class SurfaceShapes : public ::testing::TestWithParam<ShapeCase> {};

TEST_P(SurfaceShapes, ClosedManifoldOrientedWithExpectedTopology) {
  const ShapeCase& c = GetParam();
  const Lattice lat = test::lattice_where(c.dims, c.inside);
  const SurfaceMesh mesh = build_surface(lat);
  const test::MeshTopology topo = test::check_topology(mesh);
  EXPECT_TRUE(topo.problems.empty()) << c.name << ": " << topo.describe();
  EXPECT_EQ(topo.components, c.components) << c.name << ": " << topo.describe();
  EXPECT_EQ(topo.genus, c.genus) << c.name << ": " << topo.describe();
  EXPECT_EQ(topo.euler, 2 * (long(c.components) - c.genus)) << c.name << ": " << topo.describe();
  EXPECT_EQ(mesh.triangles.size() % 2, 0u);
  ASSERT_EQ(mesh.normal_of_vertex.size(), mesh.vertex_count());
  for (const auto& n : mesh.normal_of_vertex) EXPECT_NEAR(n.norm(), 1.0, 1e-12) << c.name;
}

TEST_P(SurfaceShapes, EnclosedVolumeIsCompleteCellsTimesCellVolume) {
  const ShapeCase& c = GetParam();
  const Lattice lat = test::lattice_where(c.dims, c.inside);
  const SurfaceMesh mesh = build_surface(lat);
  const double h3 = std::pow(lat.spacing_m, 3);
  const double volume = enclosed_volume_m3(mesh, element_positions_m(lat));
  EXPECT_GT(volume, 0) << c.name;
  EXPECT_NEAR(volume / h3, double(mesh.complete_cell_count), 1e-9 * double(mesh.complete_cell_count)) << c.name;
  // Voxel volume − enclosed volume = Σ (1 − w_e)·h³ exactly (w_e: dual-volume fraction).
  double shell = 0;
  for (std::size_t e = 0; e < lat.element_count(); ++e) shell += 1.0 - dual_volume_fraction(lat.neighbours(e));
  EXPECT_NEAR(double(lat.element_count()) - volume / h3, shell, 1e-9 * double(lat.element_count())) << c.name;
}

TEST_P(SurfaceShapes, NoTwoTrianglesIntersectAtRest) {
  const ShapeCase& c = GetParam();
  const Lattice lat = test::lattice_where(c.dims, c.inside);
  const SurfaceMesh mesh = build_surface(lat);
  EXPECT_EQ(test::count_rest_intersections(lat, mesh), 0u) << c.name;
}

TEST_P(SurfaceShapes, VerticesAreTheSurfaceElements) {
  const ShapeCase& c = GetParam();
  const Lattice lat = test::lattice_where(c.dims, c.inside);
  const SurfaceMesh mesh = build_surface(lat);
  const SurfaceElements surface = find_surface_elements(lat);
  const std::set<std::uint32_t> used(mesh.element_of_vertex.begin(), mesh.element_of_vertex.end());
  EXPECT_EQ(std::vector<std::uint32_t>(used.begin(), used.end()), surface.element) << c.name;
  EXPECT_EQ(mesh.surface_element_count, surface.element.size());
  EXPECT_EQ(count_surface_elements(lat), surface.element.size());
  EXPECT_EQ(mesh.split_element_count, mesh.vertex_count() - used.size());
  // The summed-direction normal and the fan normal agree in direction on these shapes.
  std::vector<int> index_of(lat.element_count(), -1);
  for (std::size_t s = 0; s < surface.element.size(); ++s) index_of[surface.element[s]] = int(s);
  std::size_t opposed = 0;
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    opposed += surface.outward_normal[std::size_t(index_of[mesh.element_of_vertex[v]])].dot(mesh.normal_of_vertex[v]) < 0;
  EXPECT_LE(opposed, mesh.split_element_count) << c.name;  // only split elements may disagree
}

TEST_P(SurfaceShapes, VolumeGradientMatchesFiniteDifferences) {
  const ShapeCase& c = GetParam();
  const Lattice lat = test::lattice_where(c.dims, c.inside);
  const SurfaceMesh mesh = build_surface(lat);
  std::vector<double> x = element_positions_m(lat);
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> jitter(-0.2 * lat.spacing_m, 0.2 * lat.spacing_m);
  for (double& v : x) v += jitter(rng);
  const std::vector<double> g = volume_gradient_m2(mesh, x);
  // V is linear in each single coordinate (a triangle's corners are distinct elements), so the
  // central difference is exact up to rounding, whatever the step.
  const double step = 1e-3 * lat.spacing_m, scale = lat.spacing_m * lat.spacing_m;
  std::set<std::uint32_t> elements(mesh.element_of_vertex.begin(), mesh.element_of_vertex.end());
  std::size_t checked = 0;
  for (const std::uint32_t e : elements) {
    if (checked++ % 7 != 0) continue;  // a sample keeps this fast on the larger shapes
    for (int k = 0; k < 3; ++k) {
      std::vector<double> xp = x, xm = x;
      xp[3 * e + k] += step;
      xm[3 * e + k] -= step;
      const double fd = (enclosed_volume_m3(mesh, xp) - enclosed_volume_m3(mesh, xm)) / (2 * step);
      EXPECT_NEAR(g[3 * e + k], fd, 1e-9 * scale) << c.name << " element " << e << " axis " << k;
    }
  }
  // Off the surface the gradient is zero; rigid translation does not change the volume.
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (std::size_t e = 0; e < lat.element_count(); ++e) {
    total += Eigen::Vector3d(g[3 * e], g[3 * e + 1], g[3 * e + 2]);
    if (!elements.count(std::uint32_t(e))) EXPECT_EQ(Eigen::Vector3d(g[3 * e], g[3 * e + 1], g[3 * e + 2]).norm(), 0.0);
  }
  EXPECT_LT(total.norm(), 1e-9 * scale * double(elements.size())) << c.name;
}

INSTANTIATE_TEST_SUITE_P(Shapes, SurfaceShapes, ::testing::ValuesIn(shape_cases()),
                         [](const auto& info) { return info.param.name; });

TEST(Surface, PinchesAreSplitOrRepairedAsDocumented) {
  auto build = [](const std::string& name) {
    for (const auto& c : shape_cases())
      if (c.name == name) return build_surface(test::lattice_where(c.dims, c.inside));
    throw std::runtime_error("no shape " + name);
  };
  const SurfaceMesh edge = build("edge_pinch");
  EXPECT_EQ(edge.split_element_count, 5u);  // the pinch column (2, 2, 0..4)
  EXPECT_EQ(edge.empty_paired_edge_count, 0u);
  const SurfaceMesh corner = build("corner_pinch");
  EXPECT_EQ(corner.split_element_count, 1u);
  const SurfaceMesh one_edge = build("cavities_touching_along_one_edge");
  EXPECT_EQ(one_edge.empty_paired_edge_count, 1u);
  EXPECT_EQ(one_edge.split_element_count, 2u);  // both ends of the edge
  const SurfaceMesh two_edges = build("cavities_touching_along_two_edges");
  EXPECT_EQ(two_edges.empty_paired_edge_count, 0u);
  EXPECT_EQ(two_edges.split_element_count, 1u);  // the middle element
}

TEST(Surface, ThinPartsHaveNoSurface) {
  // A strand and a sheet one voxel thick: no complete cell, no surface, no volume.
  const Lattice strand = test::lattice_where({8, 3, 3}, [](int, int j, int k) { return j == 1 && k == 1; });
  const SurfaceMesh s = build_surface(strand);
  EXPECT_TRUE(s.triangles.empty());
  EXPECT_EQ(s.outside_body_count, strand.element_count());
  EXPECT_EQ(enclosed_volume_m3(s, element_positions_m(strand)), 0.0);
  const Lattice sheet = test::lattice_where({6, 6, 3}, [](int, int, int k) { return k == 1; });
  EXPECT_TRUE(build_surface(sheet).triangles.empty());
  EXPECT_EQ(count_surface_elements(sheet), 0u);
  // The fin on the box: its elements off the box are outside the body.
  for (const auto& c : shape_cases())
    if (c.name == "box_with_thin_fin") {
      const Lattice lat = test::lattice_where(c.dims, c.inside);
      EXPECT_EQ(build_surface(lat).outside_body_count, 6u * 4u);  // every fin element, i = 4 included
    }
}

TEST(Surface, BoxCountsMatchClosedForms) {
  // A block of a×b×c elements: complete cells (a−1)(b−1)(c−1); boundary faces 2[(a−1)(b−1) +
  // (b−1)(c−1) + (c−1)(a−1)], two triangles each; vertices = elements on the block's faces.
  const int a = 5, b = 4, c = 6;
  const Lattice lat = test::lattice_where({a, b, c}, [](int, int, int) { return true; });
  const SurfaceMesh mesh = build_surface(lat);
  EXPECT_EQ(mesh.complete_cell_count, std::size_t((a - 1) * (b - 1) * (c - 1)));
  EXPECT_EQ(mesh.triangles.size(), std::size_t(4 * ((a - 1) * (b - 1) + (b - 1) * (c - 1) + (c - 1) * (a - 1))));
  EXPECT_EQ(mesh.vertex_count(), std::size_t(a * b * c - (a - 2) * (b - 2) * (c - 2)));
  EXPECT_EQ(mesh.split_element_count, 0u);
  // On a face (not an edge) the summed direction of the 9 missing neighbours is the face normal.
  const SurfaceElements surface = find_surface_elements(lat);
  const std::size_t on_face = std::size_t(lat.element_of_voxel[(a - 1) + a * (1 + b * 2)]);  // voxel (a−1, 1, 2)
  const auto it = std::find(surface.element.begin(), surface.element.end(), on_face);
  ASSERT_NE(it, surface.element.end());
  EXPECT_NEAR((surface.outward_normal[std::size_t(it - surface.element.begin())] - Eigen::Vector3d::UnitX()).norm(), 0.0, 1e-12);
}

TEST(Surface, MirroredLatticeFrameKeepsTheMeshOutwardInTheWorld) {
  // A CT whose voxel axes form a left-handed frame in LPS: triangles still face out (world).
  Lattice lat = test::lattice_where({8, 7, 6}, [](int i, int j, int k) { return sq(i - 3.5) + sq(j - 3) + sq(k - 2.5) <= 9.5; });
  lat.rotation = Eigen::Vector3d(-1, 1, 1).asDiagonal();
  const SurfaceMesh mesh = build_surface(lat);
  const double volume = enclosed_volume_m3(mesh, element_positions_m(lat));
  EXPECT_NEAR(volume, double(mesh.complete_cell_count) * std::pow(lat.spacing_m, 3), 1e-15);
  // Normals point away from the centre.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (std::size_t e = 0; e < lat.element_count(); ++e) centre += lat.rest_position(e);
  centre /= double(lat.element_count());
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    EXPECT_GT(mesh.normal_of_vertex[v].dot(lat.rest_position(mesh.element_of_vertex[v]) - centre), 0.0);
}

TEST(Surface, DeformedVolumeFollowsAStretch) {
  // Stretching by (1.1, 0.9, 1.2) about any point scales the enclosed volume by 1.188.
  const ShapeCase& torus = shape_cases()[4];
  const Lattice lat = test::lattice_where(torus.dims, torus.inside);
  const SurfaceMesh mesh = build_surface(lat);
  const std::vector<double> rest = element_positions_m(lat);
  std::vector<double> u(rest.size());
  const Eigen::Vector3d stretch(1.1, 0.9, 1.2), about(0.12, -0.2, 0.06);
  for (std::size_t e = 0; e < lat.element_count(); ++e)
    for (int k = 0; k < 3; ++k) u[3 * e + k] = (stretch[k] - 1) * (rest[3 * e + k] - about[k]);
  const double v0 = enclosed_volume_m3(mesh, rest), v1 = enclosed_volume_m3(mesh, element_positions_m(lat, u));
  EXPECT_NEAR(v1 / v0, 1.1 * 0.9 * 1.2, 1e-12);
}

TEST(Surface, RandomVoxelSetsGiveClosedManifoldSurfaces) {
  // Random blobs stress every local configuration, pinches of all kinds included.
  std::size_t pinched = 0, repaired = 0;
  for (unsigned seed = 1; seed <= 300; ++seed) {
    std::mt19937 rng(seed);
    const double fill = 0.55 + 0.4 * std::uniform_real_distribution<double>(0, 1)(rng);
    std::vector<std::uint8_t> occupied(9 * 9 * 9);
    for (auto& o : occupied) o = std::uniform_real_distribution<double>(0, 1)(rng) < fill;
    const Lattice lat = test::lattice_where({9, 9, 9}, [&](int i, int j, int k) { return occupied[i + 9 * (j + 9 * k)] != 0; });
    const SurfaceMesh mesh = build_surface(lat);
    const test::MeshTopology topo = test::check_topology(mesh);
    ASSERT_TRUE(topo.problems.empty()) << "seed " << seed << " fill " << fill << ": " << topo.describe();
    ASSERT_GE(topo.genus, 0) << "seed " << seed;
    const double volume = enclosed_volume_m3(mesh, element_positions_m(lat)) / std::pow(lat.spacing_m, 3);
    ASSERT_NEAR(volume, double(mesh.complete_cell_count), 1e-9 * double(mesh.complete_cell_count + 1)) << "seed " << seed;
    ASSERT_EQ(test::count_rest_intersections(lat, mesh), 0u) << "seed " << seed;
    pinched += mesh.split_element_count;
    repaired += mesh.empty_paired_edge_count;
  }
  EXPECT_GT(pinched, 0u);   // the sample does exercise pinches
  RecordProperty("split_elements", int(pinched));
  RecordProperty("empty_paired_edges", int(repaired));
  std::cout << "random sets: " << pinched << " split elements, " << repaired << " empty-paired edges\n";
}

}  // namespace
}  // namespace vb
