#include "engine/probe/triangle_geometry.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace vb {
namespace {

Vec3 vertex(const SurfaceMesh& mesh, std::span<const double> x, std::uint32_t v) {
  const std::size_t e = mesh.element_of_vertex[v];
  return Vec3(x[3 * e], x[3 * e + 1], x[3 * e + 2]);
}

/// Distance from the sphere's centre to triangle t (m).
double centre_distance(const SurfaceMesh& mesh, std::span<const double> x, std::size_t t, const Vec3& centre) {
  const Vec3 a = vertex(mesh, x, mesh.triangles[t][0]), b = vertex(mesh, x, mesh.triangles[t][1]),
             c = vertex(mesh, x, mesh.triangles[t][2]);
  const Vec3 w = nearest_on_triangle(centre, a, b, c);
  return (w[0] * a + w[1] * b + w[2] * c - centre).norm();
}

}  // namespace

Vec3 nearest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Ericson, Real-Time Collision Detection §5.1.5, as in the kernel
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {1 - v, v, 0};
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {1 - w, 0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - w, w};
  }
  const double denom = 1 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return {1 - v - w, v, w};
}

double sphere_surface_gap_m(const SurfaceMesh& mesh, std::span<const double> x, const Vec3& centre, double radius) {
  double gap = INFINITY;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) gap = std::min(gap, centre_distance(mesh, x, t, centre) - radius);
  return gap;
}

double touched_triangle_area_m2(const SurfaceMesh& mesh, std::span<const double> x, const Vec3& centre, double radius,
                                double tol) {
  double area = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (centre_distance(mesh, x, t, centre) > radius + tol) continue;
    const Vec3 a = vertex(mesh, x, mesh.triangles[t][0]), b = vertex(mesh, x, mesh.triangles[t][1]),
               c = vertex(mesh, x, mesh.triangles[t][2]);
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

}  // namespace vb
