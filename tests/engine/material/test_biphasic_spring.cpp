// The biphasic spring law g(ε) (engine/material/biphasic_spring.hpp): C¹ at ±εc, odd, linear to
// first order, the tangent beyond εc, the mapping to the seed paper's eq. 1, and the closed-form
// uniaxial stress of the bulk lattice built from it.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <ostream>

#include "engine/error.hpp"
#include "engine/material/biphasic_spring.hpp"

namespace vb {
namespace {

struct Params {
  double cubic, critical_strain;
};

void PrintTo(const Params& p, std::ostream* os) { *os << "c3 = " << p.cubic << ", εc = " << p.critical_strain; }

class Biphasic : public ::testing::TestWithParam<Params> {
 protected:
  BiphasicSpring spring() const { return biphasic_spring(GetParam().cubic, GetParam().critical_strain); }
};

TEST_P(Biphasic, IsContinuouslyDifferentiableAtTheCriticalStrain) {
  const BiphasicSpring s = spring();
  const double ec = s.critical_strain, eta = 1e-6;
  for (double sign : {1.0, -1.0}) {
    const double at = sign * ec;
    const double left = s.normalised_force(at - eta), mid = s.normalised_force(at), right = s.normalised_force(at + eta);
    // Value: one-sided differences stay O(η) on both sides (a jump would make one O(1)).
    const double slope_left = (mid - left) / eta, slope_right = (right - mid) / eta;
    // Slope: both one-sided slopes equal the tangent 1 + 3c3εc² up to the curvature 6c3εc·η/2 on
    // the cubic side.
    const double curvature_bound = 3 * s.cubic * ec * eta + 1e-8;
    EXPECT_NEAR(slope_left, s.stiffest_tangent(), curvature_bound) << "ε = " << at;
    EXPECT_NEAR(slope_right, s.stiffest_tangent(), curvature_bound) << "ε = " << at;
    EXPECT_NEAR(slope_left, slope_right, curvature_bound) << "ε = " << at;
    EXPECT_DOUBLE_EQ(s.normalised_tangent(at + sign * eta), s.stiffest_tangent()) << "beyond ε = " << at;
    EXPECT_NEAR(s.normalised_tangent(at - sign * eta), s.stiffest_tangent(), 2 * curvature_bound) << "inside ε = " << at;
  }
  // At εc the two pieces of the paper's form agree: g(εc) = εc + c3·εc³.
  EXPECT_DOUBLE_EQ(s.normalised_force(ec), ec + s.cubic * ec * ec * ec);
}

TEST_P(Biphasic, IsOdd) {
  const BiphasicSpring s = spring();
  for (double eps = 0; eps < 0.9; eps += 0.0137) {
    EXPECT_EQ(s.normalised_force(-eps), -s.normalised_force(eps)) << "ε = " << eps;
    EXPECT_EQ(s.normalised_tangent(-eps), s.normalised_tangent(eps)) << "ε = " << eps;
  }
  EXPECT_EQ(s.normalised_force(0.0), 0.0);
}

TEST_P(Biphasic, EqualsTheLinearSpringToFirstOrder) {
  const BiphasicSpring s = spring();
  for (double eps : {1e-2, 1e-3, 1e-4, 1e-6}) {
    // g(ε) = ε + c3·ε³ below εc: the relative difference from the linear law is c3·ε².
    const double e = std::min(eps, s.critical_strain);
    EXPECT_NEAR(s.normalised_force(e) / e - 1, s.cubic * e * e, 1e-12) << "ε = " << e;
  }
  EXPECT_DOUBLE_EQ(s.normalised_tangent(0), 1.0);
}

TEST_P(Biphasic, TangentBeyondTheCriticalStrainIsConstant) {
  const BiphasicSpring s = spring();
  const double ec = s.critical_strain, expected = 1 + 3 * s.cubic * ec * ec;
  EXPECT_DOUBLE_EQ(s.stiffest_tangent(), expected);
  for (double factor : {1.5, 2.0, 4.0}) {
    const double eps = std::min(factor * ec, 0.99), eta = 1e-5;
    if (eps - eta <= ec) continue;
    for (double sign : {1.0, -1.0}) {
      const double e = sign * eps;
      const double slope = (s.normalised_force(e + eta) - s.normalised_force(e - eta)) / (2 * eta);
      EXPECT_NEAR(slope, expected, 1e-8) << "ε = " << e;
      EXPECT_DOUBLE_EQ(s.normalised_tangent(e), expected) << "ε = " << e;
    }
  }
  // Inside, the tangent is 1 + 3c3ε² (the derivative of ε + c3ε³).
  const double e = 0.5 * ec, eta = 1e-6;
  EXPECT_NEAR((s.normalised_force(e + eta) - s.normalised_force(e - eta)) / (2 * eta), 1 + 3 * s.cubic * e * e, 1e-8);
}

TEST_P(Biphasic, MapsToThePapersEquationOne) {
  // F(Δl) = (K1·Δl + K2·Δl³)·L inside and (A + B(|Δl| − L·Δl_c))·sgn(Δl) beyond, with K1 = k/L,
  // K2 = k·c3/L³: the same force as k·L·g(Δl/L) for a face-diagonal spring at h = 3 mm.
  const BiphasicSpring s = spring();
  const double k = 6.0 / 35.0 * 0.003 * 4000, L = std::sqrt(2.0) * 0.003;
  const BiphasicPaperConstants c = paper_constants(s, k, L);
  EXPECT_DOUBLE_EQ(c.k1_n_m2, k / L);
  EXPECT_DOUBLE_EQ(c.k2_n_m4, k * s.cubic / (L * L * L));
  for (double eps = -0.8; eps <= 0.8; eps += 0.01) {
    const double dl = eps * L;
    EXPECT_NEAR(paper_force(c, L, dl), k * L * s.normalised_force(eps), 1e-12 * k * L) << "ε = " << eps;
  }
}

TEST_P(Biphasic, LatticeUniaxialStressIsLinearAtSmallStrainAndStiffensBeyond) {
  const BiphasicSpring s = spring();
  const double E = 3000;
  // Small strain: E and ν = 1/4 of the linear-spring lattice.
  for (double strain : {1e-6, -1e-6}) {
    const LatticeUniaxialState st = lattice_uniaxial_stress(s, E, 1 + strain);
    EXPECT_NEAR(st.nominal_stress_pa / (E * strain), 1.0, 1e-5);
    EXPECT_NEAR((st.lateral_stretch - 1) / strain, -0.25, 1e-5);
  }
  // Beyond: stiffer than the linear-spring lattice when c3 > 0, never softer.
  const BiphasicSpring linear = biphasic_spring(0, s.critical_strain);
  for (double stretch : {0.7, 0.9, 1.1, 1.3}) {
    const double P = lattice_uniaxial_stress(s, E, stretch).nominal_stress_pa;
    const double P_linear = lattice_uniaxial_stress(linear, E, stretch).nominal_stress_pa;
    EXPECT_GE(std::abs(P), std::abs(P_linear) * (1 - 1e-12)) << "λ = " << stretch;
    if (s.cubic > 0) EXPECT_GT(std::abs(P), std::abs(P_linear) * 1.01) << "λ = " << stretch;
  }
  // The virial stress is the gradient of the lattice energy: it has no stress for a rotation.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.6, Eigen::Vector3d(1, -2, 2).normalized()).toRotationMatrix();
  EXPECT_LT(lattice_nominal_stress(s, E, R).norm(), 1e-12 * E);
}

INSTANTIATE_TEST_SUITE_P(Laws, Biphasic,
                         ::testing::Values(Params{20, 0.1}, Params{0, 0.1}, Params{100, 0.2}, Params{5, 0.5}),
                         [](const auto& info) { return "case" + std::to_string(info.index); });

TEST(BiphasicSpring, RefusesImpossibleParameters) {
  EXPECT_THROW(biphasic_spring(-1, 0.1), Error);
  EXPECT_THROW(biphasic_spring(NAN, 0.1), Error);
  EXPECT_THROW(biphasic_spring(20, 0), Error);
  EXPECT_THROW(biphasic_spring(20, 1), Error);
  EXPECT_THROW(biphasic_spring(20, NAN), Error);
  MaterialSpec m;
  m.name = "gel";
  m.law = "biphasic";
  m.cubic = 20;
  m.critical_strain = 1.5;
  try {
    (void)biphasic_spring_of(m);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.location(), "materials.gel.critical_strain");
  }
}

}  // namespace
}  // namespace vb
