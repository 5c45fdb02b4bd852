#include <gtest/gtest.h>

#include "engine/error.hpp"
#include "engine/loads/anchors.hpp"
#include "engine/sim/simulator.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

AnchorSpec chest_sphere(const Vec3& rpy_deg) {
  AnchorSpec a;
  a.name = "chest";
  a.kind = AnchorSpec::Kind::Sphere;
  a.center_m = Vec3(0.01, 0.01, -0.02);
  a.radius_m = 0.026;
  a.rpy_deg = rpy_deg;
  return a;
}

class SphereAnchorPose : public ::testing::TestWithParam<Vec3> {};

TEST_P(SphereAnchorPose, MovesAnchoredElementsByExactlyThatRotation) {
  const Vec3 rpy = GetParam();
  Scene s = test::box_scene(10, 10, 10, 0.002);
  s.anchors.push_back(chest_sphere(rpy));
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -9.81);
  s.solver.dashpot_ratio = 0.2;
  s.solver.precision = Precision::Double;
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  sim.advance(50);  // held elements must stay exactly where the pose put them
  std::vector<double> u, v;
  sim.download(u, v);
  const Eigen::Matrix3d R = rotation_from_rpy_deg(rpy);
  std::size_t held = 0;
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e) {
    const Vec3 X = m.lattice.rest_position(e);
    if (!anchor_contains(s.anchors[0], X)) continue;
    ++held;
    const Vec3 expected = R * (X - s.anchors[0].center_m) + s.anchors[0].center_m;
    const Vec3 actual = X + Vec3(u[3 * e], u[3 * e + 1], u[3 * e + 2]);
    EXPECT_LT((actual - expected).norm(), 1e-15) << "element " << e;
    // rigid: distance to the sphere centre is preserved
    EXPECT_NEAR((actual - s.anchors[0].center_m).norm(), (X - s.anchors[0].center_m).norm(), 1e-15);
  }
  EXPECT_EQ(held, m.elements.held_count);
  EXPECT_GT(held, 0u);
  // the free elements start turned with it (the patient turns as a whole)
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e) {
    const Vec3 X = m.lattice.rest_position(e);
    if (anchor_contains(s.anchors[0], X)) continue;
    const Vec3 expected = R * (X - s.anchors[0].center_m) + s.anchors[0].center_m - X;
    EXPECT_LT((expected - Vec3(m.elements.displacement_m[3 * e], m.elements.displacement_m[3 * e + 1],
                               m.elements.displacement_m[3 * e + 2])).norm(), 1e-15) << "element " << e;
  }
}

INSTANTIATE_TEST_SUITE_P(Poses, SphereAnchorPose,
                         ::testing::Values(Vec3(0, 0, 5), Vec3(0, 0, -12), Vec3(3, -4, 7)),
                         [](const auto& info) { return "pose" + std::to_string(info.index); });

TEST(Anchors, RpyIsYawPitchRollAboutFixedAxes) {
  const Eigen::Matrix3d yaw = rotation_from_rpy_deg(Vec3(0, 0, 90));
  EXPECT_LT((yaw * Vec3::UnitX() - Vec3::UnitY()).norm(), 1e-12);
  const Eigen::Matrix3d roll = rotation_from_rpy_deg(Vec3(90, 0, 0));
  EXPECT_LT((roll * Vec3::UnitY() - Vec3::UnitZ()).norm(), 1e-12);
}

TEST(Anchors, AnchorHoldingNothingIsAnErrorNamingIt) {
  Scene s = test::box_scene(4, 4, 4, 0.002);
  AnchorSpec far = chest_sphere(Vec3::Zero());
  far.name = "faraway";
  far.center_m = Vec3(1, 1, 1);
  far.radius_m = 0.01;
  s.anchors.push_back(far);
  try {
    test::make_model(s);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("faraway"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("holds no element"), std::string::npos) << e.what();
  }
}

TEST(Anchors, HalfSpaceAndBoxHoldTheRightElements) {
  Scene s = test::box_scene(5, 4, 3, 0.001);
  s.anchors.push_back(test::halfspace_anchor("floor", Vec3(0, 0, 0.001), Vec3(0, 0, -1)));
  AnchorSpec box;
  box.name = "corner";
  box.kind = AnchorSpec::Kind::Box;
  box.min_m = Vec3(0.004, 0.003, 0.002);
  box.max_m = Vec3(0.006, 0.005, 0.004);
  s.anchors.push_back(box);
  const auto m = test::make_model(s);
  const AnchorPlacement p = place_anchors(m.lattice, s.anchors);
  EXPECT_EQ(p.held_per_anchor[0], 20u);  // bottom layer, 5 × 4
  EXPECT_EQ(p.held_per_anchor[1], 1u);   // one corner voxel
  EXPECT_EQ(m.elements.held_count, 21u);
}

}  // namespace
}  // namespace vb
