#pragma once
/// Host-side geometry of an inflatable torus (the kernels' twin is kernels/device_contact.cl):
/// its radii over the inflation schedule, the signed distance from its surface, and its triangle
/// mesh for viewers. World frame, SI units.
#include <Eigen/Core>

#include "engine/geometry/triangle_mesh.hpp"
#include "engine/scene/scene.hpp"

namespace vb {

struct TorusRadii {
  double minor_m = 0, major_m = 0;              ///< r and R at the time asked (m)
  double minor_rate_m_s = 0, major_rate_m_s = 0;  ///< dr/dt, dR/dt there (m/s; 0 outside the schedule)
};

/// Radii at time t: linear between knots, the first knot's before it, the last one's after it.
/// On a knot the rate is that of the segment starting there.
TorusRadii torus_radii(const TorusSpec& torus, double t_s);

/// Time of the last knot (s): the inflation is over after it.
double torus_inflation_end_s(const TorusSpec& torus);

/// Signed distance of world point x from the torus surface at time t (m, < 0 inside the tube) and
/// the outward unit normal there. On the axis (every point of the centre circle equally near) the
/// normal lies along `reference_perpendicular(axis)`.
double torus_signed_distance(const TorusSpec& torus, double t_s, const Vec3& x_m, Vec3* normal = nullptr);

/// A fixed unit vector perpendicular to `axis` (unit), used where the radial direction is undefined.
Vec3 reference_perpendicular(const Vec3& axis);

/// Closed triangle mesh of the torus surface at time t: `ring` segments around the axis times
/// `tube` segments around the tube, counter-clockwise seen from outside (normals point out).
TriangleMesh torus_mesh(const TorusSpec& torus, double t_s, int ring = 96, int tube = 32);

}  // namespace vb
