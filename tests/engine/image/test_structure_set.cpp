#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "engine/error.hpp"
#include "engine/image/structure_set.hpp"

namespace vb {
namespace {

/// A 1 × 1 × 2 mm grid, oblique-free, with two labels: a ring of 2 (a hole in it) and a block of 3.
ImageVolume ring_and_block() {
  ImageVolume v;
  v.dims = {20, 16, 6};
  v.affine_lps_m.topLeftCorner<3, 3>() = Eigen::Vector3d(0.001, 0.001, 0.002).asDiagonal();
  v.affine_lps_m.topRightCorner<3, 1>() = Eigen::Vector3d(-0.01, 0.004, -0.003);
  v.modality = "LABEL";
  v.values.assign(v.voxel_count(), 0.f);
  for (int k = 1; k < 5; ++k)
    for (int j = 2; j < 12; ++j)
      for (int i = 2; i < 10; ++i) {
        const bool hole = i >= 4 && i < 7 && j >= 5 && j < 8 && k != 4;
        v.values[v.linear_index(i, j, k)] = hole ? 0.f : 2.f;
      }
  for (int k = 0; k < 3; ++k)
    for (int j = 6; j < 14; ++j)
      for (int i = 12; i < 18; ++i) v.values[v.linear_index(i, j, k)] = 3.f;
  v.values[v.linear_index(17, 13, 2)] = 0.f;  // a notch: a non-convex outline
  v.values[v.linear_index(15, 9, 0)] = 0.f;   // a one-voxel hole touching nothing else
  return v;
}

StructureLabelRule rule_for(const std::vector<std::pair<std::string, int>>& labels) {
  StructureLabelRule r;
  for (const auto& [name, value] : labels) r.labels[name] = value;
  return r;
}

TEST(StructureSet, ContoursOfLabelsRasteriseBackToTheSameVoxels) {
  const ImageVolume labels = ring_and_block();
  const StructureSet set = structures_of_labels(labels, {{2, "ring"}, {3, "block"}});
  ASSERT_EQ(set.rois.size(), 2u);
  EXPECT_FALSE(set.rois[0].contours.empty());
  const ImageVolume back = rasterise_structures(set, labels, rule_for({{"ring", 2}, {"block", 3}}));
  ASSERT_EQ(back.values.size(), labels.values.size());
  for (std::size_t v = 0; v < labels.values.size(); ++v) ASSERT_EQ(back.values[v], labels.values[v]) << v;
  // Contours lie on voxel edges: each point half a voxel from the nearest centres in i and j.
  const Eigen::Matrix4d to_index = labels.affine_lps_m.inverse();
  for (const auto& contour : set.rois[1].contours)
    for (const Eigen::Vector3d& p : contour) {
      const Eigen::Vector3d q = (to_index * p.homogeneous()).head<3>();
      EXPECT_NEAR(std::abs(q.x() - std::round(q.x())), 0.5, 1e-9);
      EXPECT_NEAR(q.z(), std::round(q.z()), 1e-9);
    }
}

/// A square contour of half-width h (m) around (x, y) on slice k of the grid.
std::vector<Eigen::Vector3d> square(const ImageVolume& g, double i, double j, int k, double half) {
  std::vector<Eigen::Vector3d> c;
  for (const auto& [a, b] : std::vector<std::pair<double, double>>{{-1, -1}, {1, -1}, {1, 1}, {-1, 1}})
    c.push_back(g.world_of_index(Eigen::Vector3d(i + a * half, j + b * half, k)));
  return c;
}

TEST(StructureSet, VoxelCentresInsideTheContourBelongToIt) {
  const ImageVolume g = ring_and_block();
  StructureSet set;
  set.rois.push_back({1, "box", {255, 0, 0}, "", {square(g, 5, 5, 2, 2.4)}});
  const ImageVolume r = rasterise_structures(set, g, rule_for({{"box", 7}}));
  std::size_t count = 0;
  for (float v : r.values) count += v == 7.f;
  EXPECT_EQ(count, 25u);  // centres 3..7 in i and j: 2.4 voxels either side of 5
  EXPECT_EQ(r.values[r.linear_index(3, 3, 2)], 7.f);
  EXPECT_EQ(r.values[r.linear_index(2, 5, 2)], 0.f);
}

void expect_error_naming(const StructureSet& set, const ImageVolume& grid, const StructureLabelRule& rule,
                         const std::string& roi, const std::string& part) {
  try {
    rasterise_structures(set, grid, rule);
    ADD_FAILURE() << "no error for " << part;
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("ROI '" + roi + "'"), std::string::npos) << what;
    EXPECT_NE(what.find(part), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(StructureSet, BadStructuresAreOneLineErrorsNamingTheRoi) {
  ImageVolume g = ring_and_block();
  const StructureLabelRule rule = rule_for({{"a", 1}, {"b", 2}});
  StructureSet outside;
  outside.rois.push_back({1, "a", {}, "", {square(g, 18, 5, 1, 3)}});
  expect_error_naming(outside, g, rule, "a", "outside the image");
  StructureSet unmapped;
  unmapped.rois.push_back({1, "c", {}, "", {square(g, 5, 5, 1, 1)}});
  expect_error_naming(unmapped, g, rule, "c", "maps to no tissue");
  StructureSet tilted;
  std::vector<Eigen::Vector3d> t = square(g, 5, 5, 1, 1);
  t[2] = g.world_of_index(Eigen::Vector3d(6, 6, 2));
  tilted.rois.push_back({1, "a", {}, "", {t}});
  expect_error_naming(tilted, g, rule, "a", "not in one slice plane");
  StructureSet two_points;
  two_points.rois.push_back({1, "b", {}, "", {{g.world_of_index(Eigen::Vector3d(1, 1, 1)), g.world_of_index(Eigen::Vector3d(3, 3, 1))}}});
  expect_error_naming(two_points, g, rule, "b", "at least 3");
  StructureSet overlap;
  overlap.rois.push_back({1, "a", {}, "", {square(g, 5, 5, 1, 2)}});
  overlap.rois.push_back({2, "b", {}, "", {square(g, 7, 5, 1, 2)}});
  expect_error_naming(overlap, g, rule, "b", "overlaps ROI 'a'");
  g.dicom_tags["0020,0052"] = "1.2.3";
  StructureSet other_frame;
  other_frame.rois.push_back({1, "a", {}, "1.2.4", {square(g, 5, 5, 1, 1)}});
  expect_error_naming(other_frame, g, rule, "a", "frame of reference");
}

TEST(StructureSet, PriorityDecidesOverlapsFirstListedWins) {
  const ImageVolume g = ring_and_block();
  StructureSet overlap;
  overlap.rois.push_back({1, "a", {}, "", {square(g, 5, 5, 1, 2)}});
  overlap.rois.push_back({2, "b", {}, "", {square(g, 7, 5, 1, 2)}});
  StructureLabelRule rule = rule_for({{"a", 1}, {"b", 2}});
  rule.priority = {"b", "a"};
  const ImageVolume r = rasterise_structures(overlap, g, rule);
  EXPECT_EQ(r.values[r.linear_index(6, 5, 1)], 2.f);  // in both: b wins
  EXPECT_EQ(r.values[r.linear_index(4, 5, 1)], 1.f);  // in a only
  rule.priority = {"a", "b"};
  EXPECT_EQ(rasterise_structures(overlap, g, rule).values[r.linear_index(6, 5, 1)], 1.f);
}

}  // namespace
}  // namespace vb
