#include <gtest/gtest.h>

#include <cmath>

#include "engine/image/deformation_field.hpp"
#include "engine/image/image_lattice.hpp"

namespace vb {
namespace {

/// A 1 mm CT of air with a 20 × 16 × 12 voxel block of tissue (+40 HU, with a gradient in x so
/// a shift is visible), and the lattice built from it at the same spacing.
struct BlockModel {
  ImageVolume ct;
  Lattice lattice;
};

BlockModel block_setup() {
  BlockModel s;
  s.ct.dims = {40, 30, 24};
  s.ct.affine_lps_m.topLeftCorner<3, 3>() = 0.001 * Eigen::Matrix3d::Identity();
  s.ct.affine_lps_m.topRightCorner<3, 1>() = Eigen::Vector3d(-0.01, 0.02, 0.0);
  s.ct.values.assign(s.ct.voxel_count(), -1000.f);
  for (int k = 6; k < 18; ++k)
    for (int j = 7; j < 23; ++j)
      for (int i = 10; i < 30; ++i) s.ct.values[s.ct.linear_index(i, j, k)] = 40.f + 5.f * i;
  ModelSpec model;
  model.hu_classes = {{"adipose", -500, 1000, 0}};
  s.lattice = build_lattice(lattice_volume_from_image(model, s.ct, classify_image(model, s.ct, nullptr)));
  return s;
}

TEST(DeformationField, RigidShiftMovesTheTissueByExactlyTheShift) {
  BlockModel s = block_setup();
  ASSERT_EQ(s.lattice.element_count(), 20u * 16 * 12);
  const Eigen::Vector3d shift(0.003, 0, 0);  // 3 voxels along +x
  std::vector<double> u(3 * s.lattice.element_count());
  for (std::size_t e = 0; e < s.lattice.element_count(); ++e)
    for (int c = 0; c < 3; ++c) u[3 * e + c] = shift[c];
  const LatticeField field(s.lattice, u);
  const auto dvf = forward_displacement_on_grid(field, s.ct);
  EXPECT_FLOAT_EQ(dvf[3 * s.ct.linear_index(15, 10, 10)], 0.003f);  // inside
  EXPECT_FLOAT_EQ(dvf[3 * s.ct.linear_index(2, 10, 10)], 0.0f);     // outside: zero
  const WarpResult w = warp_image(s.ct, s.lattice, u);
  EXPECT_LT(w.max_fixed_point_residual_m, 1e-9);
  // Moved tissue: warped(i) = ct(i − 3) for voxels whose source lies in the block.
  for (int i = 13; i < 33; ++i)
    EXPECT_FLOAT_EQ(w.warped.values[w.warped.linear_index(i, 12, 9)], s.ct.values[s.ct.linear_index(i - 3, 12, 9)]) << i;
  EXPECT_NEAR(w.inverse_field[3 * s.ct.linear_index(20, 12, 9)], -0.003, 1e-9);
  // The 3 voxel columns the block's trailing face left are air; air outside stays air.
  EXPECT_EQ(w.vacated_voxels, 3u * 16 * 12);
  EXPECT_FLOAT_EQ(w.warped.values[w.warped.linear_index(11, 12, 9)], -1000.f);
  EXPECT_FLOAT_EQ(w.warped.values[w.warped.linear_index(2, 12, 9)], -1000.f);
}

TEST(DeformationField, LabelsMoveWithTheTissue) {
  BlockModel s = block_setup();
  ImageVolume labels = s.ct;
  for (float& v : labels.values) v = v > -500.f ? 5.f : 0.f;
  std::vector<double> u(3 * s.lattice.element_count(), 0.0);
  for (std::size_t e = 0; e < s.lattice.element_count(); ++e) u[3 * e] = 0.003;  // 3 voxels along +x
  const WarpResult w = warp_image(s.ct, s.lattice, u);
  const ImageVolume warped = warp_labels(labels, s.lattice, u, w.inverse_field);
  ASSERT_EQ(warped.values.size(), labels.values.size());
  EXPECT_EQ(warped.values[labels.linear_index(32, 12, 9)], 5.f);  // tissue arrived
  EXPECT_EQ(warped.values[labels.linear_index(11, 12, 9)], 0.f);  // tissue left
  std::size_t labelled = 0;
  for (float v : warped.values) labelled += v == 5.f;
  EXPECT_EQ(labelled, 20u * 16 * 12);
  // Label by label where the CT is: every voxel the warped CT calls tissue is labelled 5, every
  // vacated or air voxel 0 (the same pull, done again from the inverse field).
  for (std::size_t v = 0; v < labels.values.size(); ++v)
    ASSERT_EQ(warped.values[v] == 5.f, w.warped.values[v] > -500.f) << v;
}

/// A smooth non-rigid deformation (up to 1.5 mm): every solved voxel meets x + u(x) = y to the
/// tolerance, tissue that moved is found, and the result is the same run after run (slices are
/// handed to threads in whatever order they free up).
TEST(DeformationField, SmoothDeformationIsInvertedWithinTolerance) {
  BlockModel s = block_setup();
  std::vector<double> u(3 * s.lattice.element_count());
  for (std::size_t e = 0; e < s.lattice.element_count(); ++e) {
    const Eigen::Vector3d p = s.lattice.rest_position(e);
    u[3 * e] = 0.0015 * std::sin(200 * p.y());
    u[3 * e + 1] = 0.0008 * std::cos(150 * p.x());
    u[3 * e + 2] = 0.0005 * std::sin(300 * p.z() + 100 * p.x());
  }
  const LatticeField field(s.lattice, u);
  const WarpResult w = warp_image(s.ct, s.lattice, u);
  EXPECT_LT(w.max_fixed_point_residual_m, 1e-6);  // a thousandth of the 1 mm spacing
  std::size_t solved = 0;
  for (int k = 0; k < s.ct.dims[2]; ++k)
    for (int j = 0; j < s.ct.dims[1]; ++j)
      for (int i = 0; i < s.ct.dims[0]; ++i) {
        const std::size_t v = s.ct.linear_index(i, j, k);
        const Eigen::Vector3d d(w.inverse_field[3 * v], w.inverse_field[3 * v + 1], w.inverse_field[3 * v + 2]);
        if (d.isZero()) continue;
        const Eigen::Vector3d y = s.ct.world_of_index(Eigen::Vector3d(i, j, k)), x = y + d;
        EXPECT_LT((x + field.displacement_at(x) - y).norm(), 1.1e-6) << i << " " << j << " " << k;  // d is float
        ++solved;
      }
  EXPECT_GT(solved, 20u * 16 * 12 * 9 / 10);
  const WarpResult again = warp_image(s.ct, s.lattice, u);
  EXPECT_EQ(again.inverse_field, w.inverse_field);
  EXPECT_EQ(again.warped.values, w.warped.values);
  EXPECT_EQ(again.vacated_voxels, w.vacated_voxels);
}

TEST(DeformationField, LinearFieldIsInterpolatedExactlyInside) {
  BlockModel s = block_setup();
  std::vector<double> u(3 * s.lattice.element_count());
  const auto linear = [](const Eigen::Vector3d& p) { return Eigen::Vector3d(0.01 * p.x(), -0.02 * p.z(), 0.005 * p.y()); };
  for (std::size_t e = 0; e < s.lattice.element_count(); ++e) {
    const Eigen::Vector3d ue = linear(s.lattice.rest_position(e));
    for (int c = 0; c < 3; ++c) u[3 * e + c] = ue[c];
  }
  const LatticeField field(s.lattice, u);
  // Points between element centres, away from the surface.
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.0103, 0.0312, 0.0105), Eigen::Vector3d(0.0051, 0.0333, 0.0077)})
    EXPECT_LT((field.displacement_at(p) - linear(p)).norm(), 1e-12);
}

TEST(DeformationField, RasterisedLabelsCoverTheModelOnly) {
  BlockModel s = block_setup();
  std::vector<double> u(3 * s.lattice.element_count(), 0.0), ones(s.lattice.element_count(), 7.0);
  const ImageVolume r = rasterise_elements(LatticeField(s.lattice, u), s.ct, ones, 0.f);
  std::size_t covered = 0;
  for (float v : r.values) covered += v == 7.f;
  EXPECT_EQ(covered, 20u * 16 * 12);
}

}  // namespace
}  // namespace vb
