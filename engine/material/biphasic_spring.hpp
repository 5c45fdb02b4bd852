#pragma once
/// Biphasic nonlinear lattice springs (seed paper: Basafa, Sefati & Okamura, eq. 1), written
/// with a small-strain modulus so the linear-spring calibration carries over (docs/PHYSICS.md,
/// "Biphasic springs"). A connection of stiffness k = κ_d·h·E (N/m) and rest length L (m) at
/// strain ε = (|r| − L)/L pulls with
///   f = k·L·g(ε),   g(ε) = ε + c3·ε³                                            |ε| ≤ εc
///                   g(ε) = sgn(ε)·(εc + c3·εc³ + (1 + 3·c3·εc²)·(|ε| − εc))       |ε| > εc
/// cubic below the critical strain εc, linear beyond, C¹ at ±εc. The paper's constants are
/// K1 = k/L, K2 = k·c3/L³, Δl_c = εc, A = k·L·g(εc), B = k·g'(εc).
/// Host (double) implementation: the reference for the kernels and the closed forms.
#include <Eigen/Core>

#include "engine/scene/scene.hpp"

namespace vb {

struct BiphasicSpring {
  double cubic = 0;              ///< c3 ≥ 0 (dimensionless)
  double critical_strain = 0.1;  ///< εc ∈ (0, 1) (dimensionless)

  /// g(ε): spring force over k·L at strain ε (dimensionless, odd in ε)
  double normalised_force(double strain) const;
  /// g'(ε) = dg/dε: tangent stiffness over k (dimensionless)
  double normalised_tangent(double strain) const;
  /// largest tangent over k, reached at and beyond ±εc: 1 + 3·c3·εc²
  double stiffest_tangent() const;
};

/// The paper's eq. 1 constants for one connection: F(Δl) = (K1·Δl + K2·Δl³)·L inside,
/// (A + B·(|Δl| − L·Δl_c))·sgn(Δl) beyond.
struct BiphasicPaperConstants {
  double k1_n_m2 = 0;       ///< K1 = k/L (N/m²)
  double k2_n_m4 = 0;       ///< K2 = k·c3/L³ (N/m⁴)
  double critical_strain = 0;  ///< Δl_c = εc
  double a_n = 0;           ///< A = k·L·(εc + c3·εc³) (N)
  double b_n_m = 0;         ///< B = k·(1 + 3·c3·εc²) (N/m)
};

/// Throws vb::Error for c3 < 0 or εc ∉ (0, 1) (or non-finite values).
BiphasicSpring biphasic_spring(double cubic, double critical_strain);
/// The law of a material spec with law "biphasic"; errors name the material's key.
BiphasicSpring biphasic_spring_of(const MaterialSpec& material);
/// Eq. 1 constants of a connection of stiffness k (N/m) and rest length L (m).
BiphasicPaperConstants paper_constants(const BiphasicSpring& spring, double stiffness_n_m, double rest_length_m);
/// The paper's eq. 1 evaluated with those constants: force (N, tension > 0) at extension Δl (m).
double paper_force(const BiphasicPaperConstants& c, double rest_length_m, double extension_m);

/// First Piola-Kirchhoff (nominal) stress (Pa) of the bulk lattice of one biphasic tissue with
/// small-strain modulus E (Pa) under the homogeneous deformation F: the virial of one element's
/// 26 half-connections over the voxel volume h³,
///   P = (1/h³)·Σ_13 directions f_d·(F·X_d/|F·X_d|)⊗X_d,   f_d = k_d·L_d·g(|F·X_d|/L_d − 1),
/// which does not depend on h. c3 = 0 gives the linear-spring lattice.
Eigen::Matrix3d lattice_nominal_stress(const BiphasicSpring& spring, double youngs_modulus_pa, const Eigen::Matrix3d& F);

/// Uniaxial stress along z of that bulk lattice: F = diag(a, a, λ) with a solved so that the
/// lateral stress is 0.
struct LatticeUniaxialState {
  double lateral_stretch = 1;     ///< a
  double nominal_stress_pa = 0;   ///< P_zz (force over undeformed area, Pa; < 0 in compression)
};
LatticeUniaxialState lattice_uniaxial_stress(const BiphasicSpring& spring, double youngs_modulus_pa, double stretch);

}  // namespace vb
