// Host geometry of the torus device: inflation schedule, signed distance and the viewer mesh.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <numbers>

#include "engine/device/torus.hpp"

namespace vb {
namespace {

TorusSpec tilted_torus() {
  TorusSpec t;
  t.center_m = Vec3(0.01, -0.02, 0.03);
  t.axis = Vec3(1, 2, 2).normalized();
  t.schedule = {{0.5, 0.004, 0.05}, {1.5, 0.012, 0.05}, {2.0, 0.010, 0.04}};
  return t;
}

TEST(Torus, ScheduleIsPiecewiseLinearAndHeldOutside) {
  const TorusSpec t = tilted_torus();
  EXPECT_DOUBLE_EQ(torus_radii(t, 0.0).minor_m, 0.004);  // before the first knot
  EXPECT_DOUBLE_EQ(torus_radii(t, 0.0).minor_rate_m_s, 0.0);
  EXPECT_NEAR(torus_radii(t, 1.0).minor_m, 0.008, 1e-15);
  EXPECT_NEAR(torus_radii(t, 1.0).minor_rate_m_s, 0.008, 1e-15);
  EXPECT_NEAR(torus_radii(t, 1.75).major_m, 0.045, 1e-15);
  EXPECT_NEAR(torus_radii(t, 1.75).major_rate_m_s, -0.02, 1e-15);
  EXPECT_DOUBLE_EQ(torus_radii(t, 1.5).minor_m, 0.012);  // on a knot: the next segment's start
  EXPECT_NEAR(torus_radii(t, 1.5).minor_rate_m_s, -0.004, 1e-15);
  EXPECT_DOUBLE_EQ(torus_radii(t, 7.0).minor_m, 0.010);  // after the last knot
  EXPECT_DOUBLE_EQ(torus_radii(t, 7.0).major_rate_m_s, 0.0);
  EXPECT_DOUBLE_EQ(torus_inflation_end_s(t), 2.0);
}

TEST(Torus, SignedDistanceAndNormal) {
  const TorusSpec t = tilted_torus();
  const double R = 0.05, r = 0.004;  // at t = 0
  const Vec3 e = reference_perpendicular(t.axis);
  EXPECT_NEAR(e.dot(t.axis), 0.0, 1e-15);
  EXPECT_NEAR(e.norm(), 1.0, 1e-15);
  const Vec3 f = t.axis.cross(e);
  for (double angle : {0.0, 1.0, 2.5, 4.0}) {
    const Vec3 radial = std::cos(angle) * e + std::sin(angle) * f;
    Vec3 n;
    // on the centre circle: deepest, r inside
    EXPECT_NEAR(torus_signed_distance(t, 0, t.center_m + R * radial, &n), -r, 1e-15);
    // outside the tube, radially out and along the axis
    EXPECT_NEAR(torus_signed_distance(t, 0, t.center_m + (R + 0.01) * radial, &n), 0.01 - r, 1e-14);
    EXPECT_NEAR((n - radial).norm(), 0.0, 1e-12);
    EXPECT_NEAR(torus_signed_distance(t, 0, t.center_m + R * radial + 0.003 * t.axis, &n), 0.003 - r, 1e-14);
    EXPECT_NEAR((n - t.axis).norm(), 0.0, 1e-12);
  }
  // On the axis every radial direction is equally near: distance R − r, normal towards the axis.
  Vec3 n;
  EXPECT_NEAR(torus_signed_distance(t, 0, t.center_m, &n), R - r, 1e-15);
  EXPECT_NEAR((n + e).norm(), 0.0, 1e-12);
}

TEST(Torus, MeshIsClosedOutwardAndOnTheSurface) {
  const TorusSpec t = tilted_torus();
  const double time = 1.0;
  const TriangleMesh mesh = torus_mesh(t, time, 96, 32);
  const TorusRadii radii = torus_radii(t, time);
  EXPECT_EQ(mesh.vertices_m.size(), 96u * 32u);
  EXPECT_EQ(mesh.triangles.size(), 2u * 96u * 32u);
  for (const Vec3& v : mesh.vertices_m) EXPECT_NEAR(torus_signed_distance(t, time, v), 0.0, 1e-15);
  // each directed edge once, and its reverse once: closed and consistently oriented
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  double six_volume = 0;
  for (const auto& tri : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++edges[{tri[k], tri[(k + 1) % 3]}];
    const Vec3 a = mesh.vertices_m[tri[0]] - t.center_m, b = mesh.vertices_m[tri[1]] - t.center_m,
               c = mesh.vertices_m[tri[2]] - t.center_m;
    six_volume += a.dot(b.cross(c));
  }
  for (const auto& [edge, count] : edges) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(edges.count({edge.second, edge.first}), 1u);
  }
  // outward orientation: positive volume, close to 2π²·R·r² (inscribed polygons: a bit less)
  const double exact = 2 * std::numbers::pi * std::numbers::pi * radii.major_m * radii.minor_m * radii.minor_m;
  EXPECT_NEAR(six_volume / 6 / exact, 1.0, 0.01);
  EXPECT_LT(six_volume / 6, exact);
}

}  // namespace
}  // namespace vb
