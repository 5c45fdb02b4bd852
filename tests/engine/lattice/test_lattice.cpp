#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <numbers>
#include <random>

#include "engine/error.hpp"
#include "engine/lattice/dual_cells.hpp"
#include "engine/lattice/lattice.hpp"
#include "engine/lattice/voxelise.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

/// Neighbour pairs of a full a×b×c block, counted once per direction class.
std::size_t block_connections(long a, long b, long c) {
  std::size_t total = 0;
  for (const auto& d : neighbour_offsets())
    total += std::size_t((a - std::abs(d[0])) * (b - std::abs(d[1])) * (c - std::abs(d[2])));
  return total / 2;
}

TEST(Lattice, ThreeCubedBlockHas27ElementsAnd158Connections) {
  const Lattice lat = build_lattice(voxelise_shapes(test::box_scene(3, 3, 3, 0.01)));
  EXPECT_EQ(lat.element_count(), 27u);
  EXPECT_EQ(lat.connection_count, 158u);  // 54 face + 72 edge + 32 corner
  EXPECT_EQ(block_connections(3, 3, 3), 158u);
}

TEST(Lattice, BlockConnectionsMatchCountingFormula) {
  for (auto [a, b, c] : {std::array{2, 2, 2}, std::array{4, 3, 5}, std::array{1, 1, 6}}) {
    const Lattice lat = build_lattice(voxelise_shapes(test::box_scene(a, b, c, 0.002)));
    EXPECT_EQ(lat.element_count(), std::size_t(a * b * c));
    EXPECT_EQ(lat.connection_count, block_connections(a, b, c)) << a << "x" << b << "x" << c;
  }
}

TEST(Lattice, SphereElementCountMatchesVolume) {
  Scene s = test::box_scene(1, 1, 1, 0.001);
  s.model.shapes[0].kind = ShapeSpec::Kind::Sphere;
  s.model.shapes[0].center_m = Vec3(0.0003, -0.0002, 0.0001);
  s.model.shapes[0].radius_m = 0.02;
  const Lattice lat = build_lattice(voxelise_shapes(s));
  const double expected = 4.0 / 3.0 * std::numbers::pi * std::pow(0.02 / 0.001, 3);
  EXPECT_NEAR(double(lat.element_count()) / expected, 1.0, 0.01) << lat.element_count() << " vs " << expected;
}

TEST(Lattice, LaterShapesOverrideEarlierOnes) {
  Scene s = test::box_scene(10, 10, 10, 0.001);
  ShapeSpec inclusion;
  inclusion.kind = ShapeSpec::Kind::Sphere;
  inclusion.center_m = Vec3::Constant(0.005);
  inclusion.radius_m = 0.002;
  inclusion.label = "tumour";
  s.model.shapes.push_back(inclusion);
  const Lattice lat = build_lattice(voxelise_shapes(s));
  EXPECT_EQ(lat.element_count(), 1000u);
  ASSERT_EQ(lat.tissue_names.size(), 2u);
  std::size_t tumour = 0;
  for (std::size_t e = 0; e < lat.element_count(); ++e) {
    const bool inside = (lat.rest_position(e) - inclusion.center_m).norm() <= inclusion.radius_m;
    EXPECT_EQ(lat.tissue_of_element[e], inside ? 1 : 0) << "element " << e;
    tumour += inside;
  }
  EXPECT_GT(tumour, 0u);
}

TEST(Lattice, HalfEllipsoidKeepsOneSide) {
  Scene s = test::box_scene(1, 1, 1, 0.001);
  ShapeSpec& half = s.model.shapes[0];
  half.kind = ShapeSpec::Kind::HalfEllipsoid;
  half.center_m = Vec3::Zero();
  half.radii_m = Vec3(0.02, 0.015, 0.01);
  half.axis = Vec3(0, 0, 1);
  const Lattice lat = build_lattice(voxelise_shapes(s));
  const double expected = 2.0 / 3.0 * std::numbers::pi * 20 * 15 * 10;
  EXPECT_NEAR(double(lat.element_count()) / expected, 1.0, 0.03);
  for (std::size_t e = 0; e < lat.element_count(); ++e) EXPECT_GE(lat.rest_position(e).z(), 0.0);
}

TEST(Lattice, DownsamplingMergesBlocks) {
  const Scene s = test::box_scene(8, 8, 4, 0.001);
  const Lattice fine = build_lattice(voxelise_shapes(s), 1);
  const Lattice coarse = build_lattice(voxelise_shapes(s), 2);
  EXPECT_EQ(fine.element_count(), 256u);
  EXPECT_EQ(coarse.element_count(), 32u);
  EXPECT_DOUBLE_EQ(coarse.spacing_m, 0.002);
  // The coarse element centre is the centre of its 2×2×2 block of fine voxels.
  EXPECT_NEAR(coarse.rest_position(0).x(), 0.5 * (fine.rest_position(0).x() + fine.rest_position(1).x()), 1e-12);
}

TEST(Lattice, VoxelIndexRoundTripsAndNeighboursAreSymmetric) {
  const Lattice lat = build_lattice(voxelise_shapes(test::box_scene(4, 3, 5, 0.001)));
  const auto& offsets = neighbour_offsets();
  for (std::size_t e = 0; e < lat.element_count(); ++e) {
    EXPECT_EQ(lat.element_of_voxel[lat.voxel_of_element[e]], std::int32_t(e));
    const auto nb = lat.neighbours(e);
    for (int d = 0; d < 26; ++d) {
      if (nb[d] < 0) continue;
      const auto back = lat.neighbours(std::size_t(nb[d]));
      // the opposite direction of d points back to e
      int opposite = -1;
      for (int q = 0; q < 26; ++q)
        if (offsets[q][0] == -offsets[d][0] && offsets[q][1] == -offsets[d][1] && offsets[q][2] == -offsets[d][2]) opposite = q;
      EXPECT_EQ(back[opposite], std::int32_t(e));
    }
  }
}

TEST(Lattice, NoShapesIsAnError) {
  Scene s = test::box_scene(2, 2, 2, 0.001);
  s.model.shapes.clear();
  EXPECT_THROW(voxelise_shapes(s), Error);
}

TEST(Lattice, ZeroSpacingIsAnError) {
  Scene s = test::box_scene(2, 2, 2, 0.001);
  s.model.spacing_m = 0;
  try {
    voxelise_shapes(s);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("model.spacing"), std::string::npos) << e.what();
  }
}

TEST(Lattice, TooManyVoxelsIsAnErrorNamingTheExtentInMetres) {
  Scene s = test::box_scene(2, 2, 2, 0.001);  // a 2 mm box
  s.model.spacing_m = 1e-6;                   // 2,000³ voxels
  try {
    voxelise_shapes(s);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("0.002 × 0.002 × 0.002 m, 8e+09 voxels"), std::string::npos) << what;
    EXPECT_NE(what.find("lengths are in metres"), std::string::npos) << what;
  }
}

/// A coordinate of 1e300 m made a one-layer model (an out-of-range double → integer cast), and a
/// spacing of 1e-9 m printed "-9223372036854775808 voxels": both are refused before any cast.
TEST(Lattice, CoordinatesAndSpacingsOutOfRangeAreRefusedBeforeAnyCast) {
  Scene far = test::box_scene(2, 2, 2, 0.001);
  far.model.shapes[0].min_m = Vec3(1e300, 0, 0);
  far.model.shapes[0].max_m = Vec3(1e300, 0.002, 0.002);
  try {
    voxelise_shapes(far);
    FAIL() << "a shape at 1e300 m was voxelised";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("the shapes reach 1e+300 m from the origin (at most 100 m)"), std::string::npos)
        << e.what();
  }
  Scene fine = test::box_scene(2, 2, 2, 0.001);
  fine.model.shapes[0].max_m = Vec3(0.05, 0.05, 0.05);
  fine.model.spacing_m = 1e-9;
  try {
    voxelise_shapes(fine);
    FAIL() << "a 5e7³-voxel grid was accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("1.25e+23 voxels"), std::string::npos) << what;
    EXPECT_EQ(what.find("-9223372036854775808"), std::string::npos) << what;
  }
}

/// A 3.9e9-voxel model passed the size guard and died minutes later in a bare std::bad_alloc.
/// The memory is estimated before the grid is allocated, and the refusal names the estimate and
/// a spacing that fits, which then passes the same check.
TEST(Lattice, ModelsLargerThanTheMemoryAreRefusedWithASpacingThatFits) {
  Scene s = test::box_scene(2, 2, 2, 0.001);
  s.model.shapes[0].max_m = Vec3(0.3, 0.3, 0.3);  // 2.7e7 voxels, all occupied
  MemoryBudget budget;
  budget.host_bytes = std::uint64_t(1) << 30;  // 1 GiB
  std::string hint;
  try {
    voxelise_shapes(s, budget);
    FAIL() << "a 2.7e7-element model was accepted within 1 GiB";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("needs about 25.9 GiB of host memory (2.7e+07 voxels, about 2.7e+07 elements) but 1 GiB are"),
              std::string::npos)
        << what;
    hint = e.hint();
  }
  const std::size_t at = hint.find("a spacing of ");
  ASSERT_NE(at, std::string::npos) << hint;
  const double fitting_mm = std::stod(hint.substr(at + 13));
  EXPECT_GT(fitting_mm, 1.0);
  s.model.spacing_m = 1e-3 * fitting_mm;
  const LabelVolume volume = voxelise_shapes(s, budget);
  EXPECT_LT(estimated_host_bytes(double(volume.labels.size()), double(volume.labels.size())), double(budget.host_bytes));

  MemoryBudget device;
  device.device_bytes = std::uint64_t(1) << 28;  // 256 MiB
  device.device_name = "small";
  s.model.spacing_m = 0.001;
  try {
    voxelise_shapes(s, device);
    FAIL() << "a model larger than the device was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("of device memory"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'small' has 0.25 GiB"), std::string::npos) << e.what();
  }
}

TEST(Lattice, ModelWithNoElementsIsAnError) {
  Scene s = test::box_scene(1, 1, 1, 0.01);
  s.model.shapes[0].kind = ShapeSpec::Kind::Sphere;
  s.model.shapes[0].center_m = Vec3::Zero();  // a voxel corner: no voxel centre inside
  s.model.shapes[0].radius_m = 1e-4;
  const Lattice lat = build_lattice(voxelise_shapes(s));
  EXPECT_EQ(lat.element_count(), 0u);
  EXPECT_THROW(make_element_arrays(s, lat), Error);
}

}  // namespace
}  // namespace vb

namespace vb {
namespace {

std::array<Eigen::Vector3d, 8> unit_cell_corners(double h) {
  std::array<Eigen::Vector3d, 8> p;
  for (int a = 0; a < 8; ++a) p[a] = h * Eigen::Vector3d(a & 1, (a >> 1) & 1, (a >> 2) & 1);
  return p;
}

// The trilinear cell volume: det(A)·h³ for any affine map A (the gradient then cof(A)·∂V₀/∂p),
// the same under a translation, and its gradient that of its volume (central differences) for a
// cell with warped faces.
TEST(DualCells, TrilinearVolumeIsExactForAffineMapsAndItsGradientIsConsistent) {
  const double h = 0.002;
  Eigen::Matrix3d A;
  A << 1.1, 0.2, -0.1, 0.05, 0.9, 0.3, -0.2, 0.1, 1.2;
  auto p = unit_cell_corners(h);
  for (auto& x : p) x = A * x + Eigen::Vector3d(0.01, -0.02, 0.03);
  const TrilinearVolume affine = trilinear_volume(p);
  EXPECT_NEAR(affine.volume_m3, A.determinant() * h * h * h, 1e-14 * h * h * h);
  const Eigen::Matrix3d cof = A.determinant() * A.inverse().transpose();
  for (int a = 0; a < 8; ++a) {
    const Eigen::Vector3d s(a & 1 ? 1 : -1, (a >> 1) & 1 ? 1 : -1, (a >> 2) & 1 ? 1 : -1);
    EXPECT_LT((affine.gradient_m2[a] - cof * s * h * h / 4).norm(), 1e-12 * h * h) << "corner " << a;
  }
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> r(-0.3 * h, 0.3 * h);
  auto warped = unit_cell_corners(h);
  for (auto& x : warped) x += Eigen::Vector3d(r(rng), r(rng), r(rng));
  const TrilinearVolume cell = trilinear_volume(warped);
  const double step = 1e-6 * h;
  for (int a = 0; a < 8; ++a)
    for (int k = 0; k < 3; ++k) {
      auto plus = warped, minus = warped;
      plus[a][k] += step;
      minus[a][k] -= step;
      const double fd = (trilinear_volume(plus).volume_m3 - trilinear_volume(minus).volume_m3) / (2 * step);
      EXPECT_NEAR(cell.gradient_m2[a][k], fd, 1e-7 * h * h) << "corner " << a << " component " << k;
    }
}

// Volumes add up: the 8 cells of a warped cell split at ξ, η, ζ = ½ (each again trilinear, with
// corners on the parent's map) have the parent's volume, so cells that share a bilinear face tile
// the body without gaps or overlaps.
TEST(DualCells, CellVolumesAreAdditive) {
  const double h = 0.002;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> r(-0.25 * h, 0.25 * h);
  auto p = unit_cell_corners(h);
  for (auto& x : p) x += Eigen::Vector3d(r(rng), r(rng), r(rng));
  const auto map = [&](double s, double t, double w) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int a = 0; a < 8; ++a)
      x += (a & 1 ? s : 1 - s) * ((a >> 1) & 1 ? t : 1 - t) * ((a >> 2) & 1 ? w : 1 - w) * p[a];
    return x;
  };
  double children = 0;
  for (int c = 0; c < 8; ++c) {
    std::array<Eigen::Vector3d, 8> q;
    for (int a = 0; a < 8; ++a)
      q[a] = map(0.5 * ((c & 1) + (a & 1)), 0.5 * (((c >> 1) & 1) + ((a >> 1) & 1)),
                 0.5 * (((c >> 2) & 1) + ((a >> 2) & 1)));
    children += trilinear_volume(q).volume_m3;
  }
  EXPECT_NEAR(children, trilinear_volume(p).volume_m3, 1e-13 * h * h * h);
}

}  // namespace
}  // namespace vb
