#include "engine/material/hyperelastic.hpp"

#include <Eigen/Dense>
#include <cmath>

#include "engine/error.hpp"
#include "engine/scene/scene.hpp"

namespace vb {

double HyperelasticLaw::shear_modulus_pa() const {
  double mu0 = 0;
  for (int p = 0; p < terms; ++p) mu0 += 0.5 * mu_pa[p] * alpha[p];
  return mu0;
}

double HyperelasticLaw::youngs_modulus_pa() const {
  const double mu0 = shear_modulus_pa(), k = bulk_modulus_pa;
  return 9 * k * mu0 / (3 * k + mu0);
}

double HyperelasticLaw::poisson_ratio() const {
  const double mu0 = shear_modulus_pa(), k = bulk_modulus_pa;
  return (3 * k - 2 * mu0) / (2 * (3 * k + mu0));
}

double HyperelasticLaw::p_wave_modulus_pa() const { return bulk_modulus_pa + 4.0 / 3.0 * shear_modulus_pa(); }

double bulk_modulus_from(double mu, double nu) {
  require(nu > -1 && nu < 0.5, "Poisson's ratio must lie in (−1, 0.5)", "nu", "use e.g. 0.45–0.499 for tissue");
  return 2 * mu * (1 + nu) / (3 * (1 - 2 * nu));
}

HyperelasticLaw neo_hookean_from_E_nu(double E, double nu) {
  require(E > 0 && std::isfinite(E), "Young's modulus must be positive", "E");
  HyperelasticLaw law;
  law.kind = HyperelasticLaw::Kind::NeoHookean;
  law.terms = 1;
  law.mu_pa = {E / (2 * (1 + nu)), 0, 0};
  law.alpha = {2, 0, 0};
  law.bulk_modulus_pa = bulk_modulus_from(law.mu_pa[0], nu);
  return law;
}

HyperelasticLaw mooney_rivlin(double c10, double c01, double kappa) {
  HyperelasticLaw law;
  law.kind = HyperelasticLaw::Kind::MooneyRivlin;
  law.terms = 2;
  law.mu_pa = {2 * c10, -2 * c01, 0};
  law.alpha = {2, -2, 0};
  law.bulk_modulus_pa = kappa;
  require(law.shear_modulus_pa() > 0, "C10 + C01 must be positive", "c10");
  require(kappa > 0, "bulk modulus must be positive", "bulk_modulus");
  return law;
}

HyperelasticLaw ogden(const std::vector<double>& mu, const std::vector<double>& alpha, double kappa) {
  require(mu.size() >= 1 && mu.size() <= 3 && mu.size() == alpha.size(),
          "Ogden needs 1 to 3 terms with one mu and one alpha each", "mu");
  HyperelasticLaw law;
  law.kind = HyperelasticLaw::Kind::Ogden;
  law.terms = int(mu.size());
  for (std::size_t p = 0; p < mu.size(); ++p) {
    require(alpha[p] != 0 && std::isfinite(alpha[p]) && std::isfinite(mu[p]), "alpha must be nonzero and finite", "alpha");
    law.mu_pa[p] = mu[p];
    law.alpha[p] = alpha[p];
  }
  require(law.shear_modulus_pa() > 0, "the initial shear modulus ½Σμ_pα_p must be positive", "mu");
  require(kappa > 0, "bulk modulus must be positive", "bulk_modulus");
  law.bulk_modulus_pa = kappa;
  return law;
}

HyperelasticLaw law_of(const MaterialSpec& m) {
  try {
    if (m.law == "neo-hookean") {
      HyperelasticLaw law = neo_hookean_from_E_nu(m.youngs_modulus_pa, m.poisson_ratio);
      if (m.bulk_modulus_pa > 0) law.bulk_modulus_pa = m.bulk_modulus_pa;
      return law;
    }
    if (m.law == "mooney-rivlin") {
      const double mu0 = 2 * (m.c10_pa + m.c01_pa);
      return mooney_rivlin(m.c10_pa, m.c01_pa, m.bulk_modulus_pa > 0 ? m.bulk_modulus_pa : bulk_modulus_from(mu0, m.poisson_ratio));
    }
    if (m.law == "ogden") {
      double mu0 = 0;
      for (std::size_t p = 0; p < m.ogden_mu_pa.size() && p < m.ogden_alpha.size(); ++p) mu0 += 0.5 * m.ogden_mu_pa[p] * m.ogden_alpha[p];
      require(mu0 > 0, "the initial shear modulus ½Σμ_pα_p must be positive", "mu");
      return ogden(m.ogden_mu_pa, m.ogden_alpha, m.bulk_modulus_pa > 0 ? m.bulk_modulus_pa : bulk_modulus_from(mu0, m.poisson_ratio));
    }
  } catch (const Error& e) {
    throw Error(e.problem(), "materials." + m.name + (e.location().empty() ? "" : "." + e.location()), e.hint());
  }
  throw Error("law '" + m.law + "' is not hyperelastic", "materials." + m.name + ".law");
}

std::string unstable_range(const HyperelasticLaw& law) {
  // Forward differences on a fine grid, relative to the small-strain modulus 3μ₀ (uniaxial) and
  // μ₀ (shear), so round-off near λ = 1 does not count as softening.
  const double mu0 = law.shear_modulus_pa();
  constexpr int kSamples = 600;
  for (int i = 0; i < kSamples; ++i) {
    const double a = 0.5 + 1.5 * i / kSamples, b = 0.5 + 1.5 * (i + 1) / kSamples;
    if (!((uniaxial_nominal_stress(law, b) - uniaxial_nominal_stress(law, a)) / (b - a) > 1e-9 * 3 * mu0))
      return "in uniaxial stress at stretch " + std::to_string(a).substr(0, 5);
  }
  for (int i = 0; i < kSamples; ++i) {
    const double a = double(i) / kSamples, b = double(i + 1) / kSamples;
    if (!((simple_shear_stress(law, b) - simple_shear_stress(law, a)) / (b - a) > 1e-9 * mu0))
      return "in simple shear at shear amount " + std::to_string(a).substr(0, 5);
  }
  return "";
}

namespace {

/// Principal stretches λ_i and material directions N_i (columns) of C = FᵀF.
void principal_stretches(const Eigen::Matrix3d& F, Eigen::Vector3d& stretch, Eigen::Matrix3d& N) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(F.transpose() * F);
  stretch = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  N = eig.eigenvectors();
}

}  // namespace

double strain_energy(const HyperelasticLaw& law, const Eigen::Matrix3d& F) {
  Eigen::Vector3d l;
  Eigen::Matrix3d N;
  principal_stretches(F, l, N);
  const double J = F.determinant();
  const Eigen::Vector3d lb = l * std::pow(J, -1.0 / 3.0);
  double W = 0.5 * law.bulk_modulus_pa * (J - 1) * (J - 1);
  for (int p = 0; p < law.terms; ++p)
    W += law.mu_pa[p] / law.alpha[p] * (lb.array().pow(law.alpha[p]).sum() - 3);
  return W;
}

Eigen::Matrix3d first_piola(const HyperelasticLaw& law, const Eigen::Matrix3d& F) {
  Eigen::Vector3d l;
  Eigen::Matrix3d N;
  principal_stretches(F, l, N);
  const double J = F.determinant();
  const Eigen::Vector3d lb = l * std::pow(J, -1.0 / 3.0);
  // Principal Kirchhoff stresses τ_i = λ_i ∂W/∂λ_i: deviatoric Ogden part + volumetric κJ(J−1).
  Eigen::Vector3d tau = Eigen::Vector3d::Constant(law.bulk_modulus_pa * J * (J - 1));
  for (int p = 0; p < law.terms; ++p) {
    const Eigen::Vector3d la = lb.array().pow(law.alpha[p]);
    tau += law.mu_pa[p] * (la.array() - la.sum() / 3.0).matrix();
  }
  // Second Piola-Kirchhoff S = Σ τ_i/λ_i² N_i N_iᵀ, then P = F S.
  const Eigen::Matrix3d S = N * tau.cwiseQuotient(l.cwiseProduct(l)).asDiagonal() * N.transpose();
  return F * S;
}

double uniaxial_nominal_stress(const HyperelasticLaw& law, double stretch) {
  double P = 0;
  for (int p = 0; p < law.terms; ++p)
    P += law.mu_pa[p] * (std::pow(stretch, law.alpha[p] - 1) - std::pow(stretch, -law.alpha[p] / 2 - 1));
  return P;
}

double simple_shear_stress(const HyperelasticLaw& law, double gamma) {
  // In-plane principal stretches of F = I + γ e1⊗e2: λ1,2 = √(1 + γ²/4) ± γ/2, λ3 = 1; the
  // principal axes make angle θ with tan 2θ = 2/γ, so σ12 = (σ1 − σ2) sin 2θ / 2.
  const double s = std::sqrt(1 + gamma * gamma / 4), l1 = s + gamma / 2, l2 = s - gamma / 2;
  double diff = 0;
  for (int p = 0; p < law.terms; ++p) diff += law.mu_pa[p] * (std::pow(l1, law.alpha[p]) - std::pow(l2, law.alpha[p]));
  const double sin2theta = 2 / std::sqrt(4 + gamma * gamma);
  return 0.5 * diff * sin2theta;
}

}  // namespace vb
