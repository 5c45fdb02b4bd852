#pragma once
/// Host copy of the indenters' geometry (kernels/lattice_forces.cl, indenter_distance): signed
/// distance from the surface of an indenter whose reference point is at `at_m`.
#include "engine/scene/scene.hpp"

namespace vb {

/// Signed distance (m, < 0 inside) from the indenter's surface to the world point x.
double indenter_signed_distance(const IndenterSpec& indenter, const Vec3& at_m, const Vec3& x_m);

}  // namespace vb
