#include "engine/device/torus.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

namespace vb {

TorusRadii torus_radii(const TorusSpec& torus, double t) {
  const auto& k = torus.schedule;
  TorusRadii r{k.front().minor_radius_m, k.front().major_radius_m, 0, 0};
  if (k.size() == 1 || t < k.front().time_s) return r;
  for (std::size_t i = 0; i + 1 < k.size(); ++i) {
    if (t >= k[i + 1].time_s) continue;
    const double span = k[i + 1].time_s - k[i].time_s, s = (t - k[i].time_s) / span;
    r.minor_m = k[i].minor_radius_m + s * (k[i + 1].minor_radius_m - k[i].minor_radius_m);
    r.major_m = k[i].major_radius_m + s * (k[i + 1].major_radius_m - k[i].major_radius_m);
    r.minor_rate_m_s = (k[i + 1].minor_radius_m - k[i].minor_radius_m) / span;
    r.major_rate_m_s = (k[i + 1].major_radius_m - k[i].major_radius_m) / span;
    return r;
  }
  return {k.back().minor_radius_m, k.back().major_radius_m, 0, 0};
}

double torus_inflation_end_s(const TorusSpec& torus) { return torus.schedule.back().time_s; }

Vec3 reference_perpendicular(const Vec3& axis) {
  // The coordinate axis least aligned with `axis`, made perpendicular to it.
  Eigen::Index i = 0;
  axis.cwiseAbs().minCoeff(&i);
  return (Vec3::Unit(i) - axis * axis[i]).normalized();
}

double torus_signed_distance(const TorusSpec& torus, double t, const Vec3& x, Vec3* normal) {
  const TorusRadii r = torus_radii(torus, t);
  const Vec3 q = x - torus.center_m;
  const double z = q.dot(torus.axis);
  const Vec3 p = q - z * torus.axis;
  const double rho = p.norm();
  const Vec3 e = rho > 0 ? Vec3(p / rho) : reference_perpendicular(torus.axis);
  const double dx = rho - r.major_m, d = std::hypot(dx, z);
  if (normal) *normal = d > 0 ? Vec3((dx * e + z * torus.axis) / d) : e;
  return d - r.minor_m;
}

TriangleMesh torus_mesh(const TorusSpec& torus, double t, int ring, int tube) {
  const TorusRadii r = torus_radii(torus, t);
  const Vec3 a = torus.axis, e1 = reference_perpendicular(a), e2 = a.cross(e1);
  TriangleMesh mesh;
  mesh.vertices_m.reserve(std::size_t(ring) * tube);
  for (int i = 0; i < ring; ++i) {
    const double u = 2 * std::numbers::pi * i / ring;
    const Vec3 radial = std::cos(u) * e1 + std::sin(u) * e2;
    for (int j = 0; j < tube; ++j) {
      const double v = 2 * std::numbers::pi * j / tube;
      const Vec3 n = std::cos(v) * radial + std::sin(v) * a;
      mesh.vertices_m.push_back(torus.center_m + r.major_m * radial + r.minor_m * n);
    }
  }
  const auto id = [&](int i, int j) { return std::uint32_t(((i + ring) % ring) * tube + (j + tube) % tube); };
  for (int i = 0; i < ring; ++i)
    for (int j = 0; j < tube; ++j) {
      // (radial, e2-ward, axis) is right-handed, so walking +u then +v has the outward normal
      // (∂/∂u × ∂/∂v points out of the tube).
      mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return mesh;
}

}  // namespace vb
