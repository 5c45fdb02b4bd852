#pragma once
/// Hyperelastic laws: generalised Ogden with a deviatoric/volumetric split (main paper eqs. 6–9),
/// and neo-Hookean and Mooney-Rivlin as its named special cases. Host (double) implementation:
/// the reference for the OpenCL kernels and the source of closed-form validation curves.
///   W = Σ_p μ_p/α_p (λ̄1^α_p + λ̄2^α_p + λ̄3^α_p − 3) + κ/2 (J − 1)²,   λ̄_i = J^(−1/3) λ_i
#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"

namespace vb {

struct HyperelasticLaw {
  enum class Kind { NeoHookean, MooneyRivlin, Ogden };
  Kind kind = Kind::NeoHookean;
  int terms = 1;                            ///< N (≤ 3)
  std::array<double, 3> mu_pa{0, 0, 0};     ///< μ_p (Pa)
  std::array<double, 3> alpha{2, 0, 0};     ///< α_p
  double bulk_modulus_pa = 0;               ///< κ (Pa)

  /// initial shear modulus μ₀ = ½ Σ μ_p α_p (Pa)
  double shear_modulus_pa() const;
  /// small-strain Young's modulus E = 9κμ₀/(3κ + μ₀) (Pa)
  double youngs_modulus_pa() const;
  double poisson_ratio() const;
  /// P-wave modulus κ + 4/3 μ₀ (Pa): sets the fastest wave and so the time step
  double p_wave_modulus_pa() const;
};

/// Neo-Hookean from E and ν: μ = E / (2(1 + ν)), κ = E / (3(1 − 2ν)). Throws for ν ∉ (−1, 0.5).
HyperelasticLaw neo_hookean_from_E_nu(double youngs_modulus_pa, double poisson_ratio);
/// Mooney-Rivlin W = C10(Ī1 − 3) + C01(Ī2 − 3) + κ/2 (J−1)²: Ogden N = 2, α = (2, −2), μ = (2C10, −2C01).
HyperelasticLaw mooney_rivlin(double c10_pa, double c01_pa, double bulk_modulus_pa);
/// Generalised Ogden; throws for N ∉ [1, 3], α_p = 0, or μ₀ ≤ 0.
HyperelasticLaw ogden(const std::vector<double>& mu_pa, const std::vector<double>& alpha, double bulk_modulus_pa);
/// Bulk modulus from the initial shear modulus and ν.
double bulk_modulus_from(double shear_modulus_pa, double poisson_ratio);

/// The law of a hyperelastic material spec (law neo-hookean, mooney-rivlin or ogden); throws
/// vb::Error naming the material for missing or impossible parameters.
HyperelasticLaw law_of(const MaterialSpec& material);

/// Strain energy density W(F) (J/m³).
double strain_energy(const HyperelasticLaw& law, const Eigen::Matrix3d& F);
/// First Piola-Kirchhoff stress P = ∂W/∂F (Pa), via principal stretches.
Eigen::Matrix3d first_piola(const HyperelasticLaw& law, const Eigen::Matrix3d& F);

/// Closed-form nominal stress (force / undeformed area, Pa) of an incompressible sample in
/// uniaxial stress at stretch λ: Σ μ_p (λ^(α_p − 1) − λ^(−α_p/2 − 1)) (liver paper eq. 3 / A).
double uniaxial_nominal_stress(const HyperelasticLaw& law, double stretch);
/// Closed-form Cauchy shear stress σ12 of incompressible simple shear with amount γ, from the
/// principal stretches of F = I + γ e1⊗e2 (exact for every Ogden law).
double simple_shear_stress(const HyperelasticLaw& law, double gamma);

/// Where the law stops being stable in Drucker's sense within tissue's range, as words ("in
/// uniaxial stress at stretch 0.9"): the first uniaxial stretch λ ∈ [0.5, 2] at which the nominal
/// stress does not rise with λ, or the first shear amount γ ∈ [0, 1] at which the shear stress does
/// not rise with γ; empty when it is stable throughout. Neo-Hookean, and Mooney-Rivlin and Ogden
/// with C01 ≥ 0 and every μ_p·α_p > 0, always are.
std::string unstable_range(const HyperelasticLaw& law);

}  // namespace vb
