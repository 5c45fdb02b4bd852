#include "engine/material/biphasic_spring.hpp"

#include <algorithm>
#include <cmath>

#include "engine/error.hpp"
#include "engine/lattice/lattice.hpp"
#include "engine/material/linear_spring.hpp"

namespace vb {

double BiphasicSpring::normalised_force(double eps) const {
  const double a = std::abs(eps), ec = critical_strain;
  if (a <= ec) return eps * (1 + cubic * eps * eps);
  return std::copysign(ec * (1 + cubic * ec * ec) + stiffest_tangent() * (a - ec), eps);
}

double BiphasicSpring::normalised_tangent(double eps) const {
  const double a = std::min(std::abs(eps), critical_strain);
  return 1 + 3 * cubic * a * a;
}

double BiphasicSpring::stiffest_tangent() const { return 1 + 3 * cubic * critical_strain * critical_strain; }

BiphasicSpring biphasic_spring(double cubic, double critical_strain) {
  require(cubic >= 0 && std::isfinite(cubic), "the cubic coefficient must be ≥ 0", "cubic");
  require(critical_strain > 0 && critical_strain < 1, "the critical strain must lie in (0, 1)", "critical_strain",
          "e.g. 0.1");
  BiphasicSpring s;
  s.cubic = cubic;
  s.critical_strain = critical_strain;
  return s;
}

BiphasicSpring biphasic_spring_of(const MaterialSpec& m) {
  require(m.law == "biphasic", "law '" + m.law + "' is not biphasic", "materials." + m.name + ".law");
  try {
    return biphasic_spring(m.cubic, m.critical_strain);
  } catch (const Error& e) {
    throw Error(e.problem(), "materials." + m.name + "." + e.location(), e.hint());
  }
}

BiphasicPaperConstants paper_constants(const BiphasicSpring& s, double k, double L) {
  BiphasicPaperConstants c;
  c.k1_n_m2 = k / L;
  c.k2_n_m4 = k * s.cubic / (L * L * L);
  c.critical_strain = s.critical_strain;
  c.a_n = k * L * s.normalised_force(s.critical_strain);
  c.b_n_m = k * s.stiffest_tangent();
  return c;
}

double paper_force(const BiphasicPaperConstants& c, double L, double dl) {
  if (std::abs(dl / L) <= c.critical_strain) return (c.k1_n_m2 * dl + c.k2_n_m4 * dl * dl * dl) * L;
  return std::copysign(c.a_n + c.b_n_m * (std::abs(dl) - L * c.critical_strain), dl);
}

Eigen::Matrix3d lattice_nominal_stress(const BiphasicSpring& s, double E, const Eigen::Matrix3d& F) {
  // Per direction, with k = κ_d·E·h, L = |d|·h, X = h·d, |F·X| = h·|F·d|, the h's cancel:
  // f·(F·X/|F·X|)⊗X / h³ = κ_d·E·|d|·g(ε_d)·(F·d/|F·d|)⊗d. Half of each of the 26 directions.
  const auto& offsets = neighbour_offsets();
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
  for (int d = 0; d < 26; ++d) {
    const Eigen::Vector3d dX(offsets[d][0], offsets[d][1], offsets[d][2]);
    const Eigen::Vector3d dx = F * dX;
    const double rest = linear_spring::rest_length_factor(d), len = dx.norm();
    const double f = 0.5 * linear_spring::kappa(d) * E * rest * s.normalised_force(len / rest - 1);
    P += f * (dx / len) * dX.transpose();
  }
  return P;
}

LatticeUniaxialState lattice_uniaxial_stress(const BiphasicSpring& s, double E, double stretch) {
  // P_xx grows with the lateral stretch a: bisect for P_xx = 0.
  const auto stress = [&](double a) { return lattice_nominal_stress(s, E, Eigen::Vector3d(a, a, stretch).asDiagonal()); };
  double lo = 0.2, hi = 3.0;
  for (int it = 0; it < 200 && hi - lo > 1e-15; ++it) {
    const double mid = 0.5 * (lo + hi);
    (stress(mid)(0, 0) > 0 ? hi : lo) = mid;
  }
  LatticeUniaxialState state;
  state.lateral_stretch = 0.5 * (lo + hi);
  state.nominal_stress_pa = stress(state.lateral_stretch)(2, 2);
  return state;
}

}  // namespace vb
