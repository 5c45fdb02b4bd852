#pragma once
/// Linear lattice springs: stiffness per connection from Young's modulus and spacing.
///
/// For the 26-neighbour cubic lattice the small-strain elastic constants are
///   C11 = (k_face + 2·k_edge + 4/3·k_corner)/h,  C12 = C44 = (k_edge + 4/3·k_corner)/h,
/// isotropic when k_face = k_edge + 8/3·k_corner, which fixes ν = 1/4 and E = 5/2·C44.
/// We choose k_edge = k_corner, giving k = κ·E·h with κ_face = 22/35, κ_edge = κ_corner = 6/35.
/// Full derivation: docs/PHYSICS.md.

namespace vb::linear_spring {

inline constexpr double kappa_face = 22.0 / 35.0;
inline constexpr double kappa_edge = 6.0 / 35.0;
inline constexpr double kappa_corner = 6.0 / 35.0;
inline constexpr double poisson_ratio = 0.25;

/// κ of neighbour direction d (index into neighbour_offsets())
double kappa(int d);
/// |offset| of direction d in spacings: 1, √2 or √3
double rest_length_factor(int d);

/// Spring constant (N/m) of connection d between elements with moduli Ei, Ej (Pa): every
/// existing connection carries its full bulk stiffness (docs/PHYSICS.md explains the surface).
inline double stiffness(int d, double h, double Ei, double Ej) {
  return kappa(d) * h * (2.0 * Ei * Ej / (Ei + Ej));
}

}  // namespace vb::linear_spring
