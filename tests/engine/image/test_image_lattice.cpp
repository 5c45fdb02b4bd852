#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "engine/error.hpp"
#include "engine/image/image_lattice.hpp"

namespace vb {
namespace {

/// An oblique CT (rotated axes, 1 × 1.5 × 2.5 mm voxels) of air with a box of "fat" (−100 HU)
/// holding a cube of "bone" (+700 HU) at one corner.
ImageVolume oblique_ct(Eigen::Matrix3d& R) {
  R = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  ImageVolume ct;
  ct.dims = {40, 30, 20};
  ct.affine_lps_m.topLeftCorner<3, 3>() = R * Eigen::Vector3d(0.001, 0.0015, 0.0025).asDiagonal();
  ct.affine_lps_m.topRightCorner<3, 1>() = Eigen::Vector3d(0.05, -0.02, 0.1);
  ct.values.assign(ct.voxel_count(), -1000.f);
  for (int k = 4; k < 16; ++k)
    for (int j = 5; j < 25; ++j)
      for (int i = 10; i < 30; ++i) ct.values[ct.linear_index(i, j, k)] = (i < 15 && j < 10 && k < 8) ? 700.f : -100.f;
  return ct;
}

ModelSpec hu_model() {
  ModelSpec m;
  m.image_path = "ct";
  m.hu_classes = {{"air", -2000, -500, 0}, {"adipose", -500, 200, 0}, {"bone", 200, 3000, 0}};
  return m;
}

TEST(ImageLattice, ObliqueCtBecomesARotatedIsotropicLattice) {
  Eigen::Matrix3d R;
  const ImageVolume ct = oblique_ct(R);
  ModelSpec model = hu_model();
  model.spacing_m = 0.0025;
  const TissueMap map = classify_image(model, ct, nullptr);
  ASSERT_EQ(map.tissue_names, (std::vector<std::string>{"adipose", "bone"}));
  const Lattice lat = build_lattice(lattice_volume_from_image(model, ct, map));
  EXPECT_LT((lat.rotation - R).cwiseAbs().maxCoeff(), 1e-12);
  // Box volume 20 × 30 × 30 mm = 18 cm³ → 18e-6 / 0.0025³ = 1152 elements.
  EXPECT_NEAR(double(lat.element_count()), 1152.0, 1152 * 0.05);
  // Every element's centre lies in the box (in CT index space, with half a lattice voxel slack).
  const Eigen::Matrix4d inv = ct.affine_lps_m.inverse();
  for (std::size_t e = 0; e < lat.element_count(); ++e) {
    const Eigen::Vector3d idx = (inv * lat.rest_position(e).homogeneous()).head<3>();
    EXPECT_GT(idx.x(), 9.5 - 1.25);
    EXPECT_LT(idx.x(), 29.5 + 1.25);
    EXPECT_GT(idx.z(), 3.5 - 0.5);
    EXPECT_LT(idx.z(), 15.5 + 0.5);
  }
}

TEST(ImageLattice, LabelVolumeWithTableKeepAndRoi) {
  Eigen::Matrix3d R;
  const ImageVolume ct = oblique_ct(R);
  ImageVolume labels = ct;
  for (float& v : labels.values) v = v > 200 ? 5.f : v > -500 ? 2.f : 0.f;
  ModelSpec model;
  model.image_path = "ct";
  model.labels_path = "labels";
  model.label_table = {{2, "adipose"}, {5, "bone"}};
  model.keep = {"adipose"};
  const TissueMap kept = classify_image(model, ct, &labels);
  std::size_t bone = 0, fat = 0;
  for (std::size_t v = 0; v < kept.tissue.size(); ++v) {
    bone += labels.values[v] == 5.f && kept.tissue[v] != 0;
    fat += kept.tissue[v] != 0;
  }
  EXPECT_EQ(bone, 0u) << "a tissue left out of model.keep is never built";
  EXPECT_EQ(fat, 20u * 20 * 12 - 5 * 5 * 4);
  // An ROI that excludes everything is an error naming the model.
  model.roi_m = std::make_pair(Eigen::Vector3d::Constant(5.0), Eigen::Vector3d::Constant(6.0));
  EXPECT_THROW(classify_image(model, ct, &labels), Error);
}

TEST(ImageLattice, MismatchedLabelGridAndUnknownKeptTissueAreErrors) {
  Eigen::Matrix3d R;
  const ImageVolume ct = oblique_ct(R);
  ImageVolume labels = ct;
  labels.affine_lps_m(0, 3) += 0.001;
  ModelSpec model;
  model.label_table = {{2, "adipose"}};
  EXPECT_THROW(classify_image(model, ct, &labels), Error);
  ModelSpec hu = hu_model();
  hu.keep = {"tumour"};
  try {
    classify_image(hu, ct, nullptr);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("tumour"), std::string::npos);
  }
}

}  // namespace
}  // namespace vb
