#include <gtest/gtest.h>

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
