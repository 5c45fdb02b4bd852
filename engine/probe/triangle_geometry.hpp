#pragma once
/// Host copy of triangle contact's geometry (kernels/triangle_contact.cl): the point of a surface
/// triangle nearest a sphere's centre, the sphere's gap to the surface and the touched area.
#include <span>

#include "engine/scene/scene.hpp"
#include "engine/surface/surface_mesh.hpp"

namespace vb {

/// Barycentric weights (w_a, w_b, w_c) of the point of triangle (a, b, c) nearest p.
Vec3 nearest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Smallest distance from a sphere (centre, radius) to the surface triangles (m, < 0: they
/// overlap). `x_m`: element positions (n×3, world frame).
double sphere_surface_gap_m(const SurfaceMesh& mesh, std::span<const double> x_m, const Vec3& centre_m, double radius_m);

/// Summed area (m²) of the surface triangles the sphere reaches within `tol_m`.
double touched_triangle_area_m2(const SurfaceMesh& mesh, std::span<const double> x_m, const Vec3& centre_m,
                                double radius_m, double tol_m);

}  // namespace vb
