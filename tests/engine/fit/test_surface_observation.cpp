// The label-map observation of inverse fitting (docs/FIT.md, "Observation from a label map"): the
// exact distance transform against brute force, the signed distance field's zero on voxel faces,
// and surface distances of a translated box (only the motion normal to a surface counts).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "engine/error.hpp"
#include "engine/fit/deformed_labels.hpp"
#include "engine/fit/signed_distance.hpp"
#include "engine/fit/surface_observation.hpp"
#include "engine/lattice/voxelise.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

TEST(SignedDistance, ExactTransformMatchesBruteForceOnAnAnisotropicGrid) {
  const std::array<int, 3> dims = {9, 7, 6};
  const Eigen::Vector3d h(0.001, 0.0015, 0.002);
  std::mt19937 random(5);
  std::vector<std::uint8_t> feature(std::size_t(dims[0] * dims[1] * dims[2]));
  for (auto& f : feature) f = random() % 11 == 0;
  const std::vector<double> d2 = squared_distance_transform(feature, dims, h);
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i) {
        double best = INFINITY;
        for (int c = 0; c < dims[2]; ++c)
          for (int b = 0; b < dims[1]; ++b)
            for (int a = 0; a < dims[0]; ++a)
              if (feature[std::size_t(a + dims[0] * (b + dims[1] * c))])
                best = std::min(best, std::pow((a - i) * h[0], 2) + std::pow((b - j) * h[1], 2) + std::pow((c - k) * h[2], 2));
        EXPECT_NEAR(d2[std::size_t(i + dims[0] * (j + dims[1] * k))], best, 1e-15) << i << " " << j << " " << k;
      }
}

TEST(SignedDistance, ZeroOnTheFacesNegativeInside) {
  ImageVolume grid;
  grid.dims = {20, 20, 20};
  grid.affine_lps_m.topLeftCorner<3, 3>() *= 0.001;  // 1 mm voxels, voxel (0,0,0) at the origin
  std::vector<std::uint8_t> inside(grid.voxel_count(), 0);
  for (int k = 5; k < 15; ++k)  // a 10 mm cube: faces at 4.5 and 14.5 mm
    for (int j = 5; j < 15; ++j)
      for (int i = 5; i < 15; ++i) inside[grid.linear_index(i, j, k)] = 1;
  const SignedDistanceField phi(grid, inside, "test");
  EXPECT_NEAR(phi.at(Eigen::Vector3d(0.0045, 0.0095, 0.0095)), 0.0, 1e-9);  // on a face
  EXPECT_NEAR(phi.at(Eigen::Vector3d(0.0025, 0.0095, 0.0095)), 0.002, 1e-9);
  EXPECT_NEAR(phi.at(Eigen::Vector3d(0.0075, 0.0095, 0.0095)), -0.003, 1e-9);
  EXPECT_NEAR(phi.at(Eigen::Vector3d(0.0095, 0.0095, 0.0163)), 0.0018, 1e-9);  // between centres: trilinear
  EXPECT_THROW(SignedDistanceField(grid, std::vector<std::uint8_t>(grid.voxel_count(), 0), "empty"), Error);
}

TEST(SurfaceObservation, TranslatedBoxOnlyTheNormalMotionCounts) {
  const double h = 0.003;
  const Scene s = test::box_scene(6, 6, 4, h);
  const Lattice lattice = build_lattice(voxelise_shapes(s));
  const std::size_t n = lattice.element_count();
  // the observation: the box moved 1.5 mm along −z (two label voxels of 0.75 mm)
  const Eigen::Vector3d t(0, 0, -0.0015);
  std::vector<double> moved(3 * n), still(3 * n, 0.0), sideways(3 * n);
  for (std::size_t e = 0; e < n; ++e)
    for (int a = 0; a < 3; ++a) {
      moved[3 * e + a] = t[a];
      sideways[3 * e + a] = t[a] + (a == 0 ? 0.0007 : 0.0);
    }
  const ImageVolume labels = deformed_label_map(lattice, moved, {1}, 4);
  const std::vector<SurfaceRegion> regions = surface_regions(s, lattice, {});
  ASSERT_EQ(regions.size(), 1u);
  EXPECT_EQ(regions[0].name, "body");
  const SurfaceData data(labels, lattice, regions, std::vector<bool>(n, true), [](const Eigen::Vector3d&) { return true; },
                         0.001);
  EXPECT_EQ(data.points(), std::size_t(2 * (6 * 6 + 6 * 4 + 6 * 4)));  // every face of the box
  EXPECT_LT(data.stats(moved).max_m, 1e-6);                        // the true motion lands on it
  // unmoved: the z faces lie 1.5 mm off (outside above, inside below), the side faces on it
  const ResidualRows rows = data.rows(still);
  int top = 0, bottom = 0, bottom_exact = 0, side = 0, side_exact = 0;
  for (Eigen::Index k = 0; k < rows.value_m.size(); ++k) {
    const double d = rows.value_m[k];
    EXPECT_DOUBLE_EQ(rows.weight_per_m2[k], 1e6);
    if (d > 0.001) {
      EXPECT_NEAR(d, 0.0015, 1e-6);
      ++top;
    } else if (d < -0.001) {
      // the inside distance is exact away from the box's edges; at them the centre-to-centre
      // transform, interpolated, comes short by less than half a label voxel
      EXPECT_NEAR(d, -0.0015, 0.375e-3);
      ++bottom;
      bottom_exact += std::abs(d + 0.0015) < 1e-6;
    } else {  // side faces: on the moved sides, the top layer's on the moved top edge (the same shortfall)
      EXPECT_LT(std::abs(d), 0.375e-3);
      ++side;
      side_exact += std::abs(d) < 1e-6;
    }
  }
  EXPECT_EQ(top, 36);
  EXPECT_EQ(bottom, 36);
  EXPECT_GE(bottom_exact, 16);  // the 4×4 faces away from the edges
  EXPECT_EQ(side, 2 * (6 * 4 + 6 * 4));
  EXPECT_EQ(side_exact, 2 * (6 * 3 + 6 * 3));  // the three lower layers
  // a tangential slip of the top and bottom faces is invisible to them: only x faces see it
  const std::vector<double> slip = data.distances(sideways);
  int seen = 0;
  for (double d : slip) seen += std::abs(d) > 1e-4;
  EXPECT_EQ(seen, 2 * 6 * 4);
  EXPECT_THROW(surface_regions(s, lattice, {7}), Error);
}

}  // namespace
}  // namespace vb
