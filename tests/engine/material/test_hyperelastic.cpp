#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "engine/error.hpp"
#include "engine/material/hyperelastic.hpp"

namespace vb {
namespace {

struct LawCase {
  const char* name;
  HyperelasticLaw law;
};

std::vector<LawCase> laws() {
  const double kappa = 1000 * 1000.0;  // κ/μ ≈ 1000: ν ≈ 0.4995
  return {{"neo_hookean", neo_hookean_from_E_nu(3000, 0.4995)},
          {"mooney_rivlin", mooney_rivlin(400, 100, kappa)},
          {"ogden_two_term", ogden({1200, -300}, {4, -2}, kappa)}};
}

class Law : public ::testing::TestWithParam<LawCase> {};

TEST_P(Law, StressIsTheEnergyDerivative) {
  const HyperelasticLaw& law = GetParam().law;
  Eigen::Matrix3d F;
  F << 1.2, 0.1, -0.05, 0.02, 0.85, 0.1, -0.03, 0.04, 1.05;
  const Eigen::Matrix3d P = first_piola(law, F);
  const double h = 1e-6;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Eigen::Matrix3d Fp = F, Fm = F;
      Fp(i, j) += h;
      Fm(i, j) -= h;
      const double numeric = (strain_energy(law, Fp) - strain_energy(law, Fm)) / (2 * h);
      EXPECT_NEAR(P(i, j), numeric, 1e-5 * law.bulk_modulus_pa * 1e-3 + 1e-4 * std::abs(numeric)) << i << j;
    }
}

TEST_P(Law, RigidRotationHasNoStressAndStressIsObjective) {
  const HyperelasticLaw& law = GetParam().law;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  EXPECT_LT(first_piola(law, R).norm(), 1e-9 * law.shear_modulus_pa());
  Eigen::Matrix3d F;
  F << 1.1, 0.2, 0, 0, 0.9, 0.05, 0.1, 0, 1.0;
  EXPECT_LT((first_piola(law, R * F) - R * first_piola(law, F)).norm(), 1e-9 * first_piola(law, F).norm());
}

TEST_P(Law, UniaxialStressMatchesIncompressibleClosedForm) {
  const HyperelasticLaw& law = GetParam().law;
  for (double stretch : {0.5, 0.7, 0.9, 1.1, 1.3}) {
    // Lateral stretch giving zero lateral stress (bisection on P22).
    double lo = 0.5, hi = 2.0;
    for (int it = 0; it < 100; ++it) {
      const double mid = 0.5 * (lo + hi);
      const double p22 = first_piola(law, Eigen::Vector3d(stretch, mid, mid).asDiagonal())(1, 1);
      (p22 > 0 ? hi : lo) = mid;
    }
    const double lateral = 0.5 * (lo + hi);
    const double P11 = first_piola(law, Eigen::Vector3d(stretch, lateral, lateral).asDiagonal())(0, 0);
    const double exact = uniaxial_nominal_stress(law, stretch);
    EXPECT_NEAR(P11 / exact, 1.0, 0.01) << GetParam().name << " stretch " << stretch;  // finite κ: < 1%
  }
}

TEST_P(Law, SimpleShearMatchesClosedForm) {
  const HyperelasticLaw& law = GetParam().law;
  for (double gamma : {0.05, 0.3}) {
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    F(0, 1) = gamma;
    const Eigen::Matrix3d sigma = first_piola(law, F) * F.transpose() / F.determinant();
    EXPECT_NEAR(sigma(0, 1) / simple_shear_stress(law, gamma), 1.0, 1e-9) << GetParam().name << " γ " << gamma;
  }
}

TEST_P(Law, SmallStrainLimitIsLinearElasticity) {
  const HyperelasticLaw& law = GetParam().law;
  const double mu = law.shear_modulus_pa(), lambda = law.bulk_modulus_pa - 2 * mu / 3;
  Eigen::Matrix3d grad;
  grad << 1, 2, -1, 0.5, -1, 0.3, 2, 0, 0.7;
  grad *= 1e-6;
  const Eigen::Matrix3d eps = 0.5 * (grad + grad.transpose());
  const Eigen::Matrix3d linear = lambda * eps.trace() * Eigen::Matrix3d::Identity() + 2 * mu * eps;
  const Eigen::Matrix3d P = first_piola(law, Eigen::Matrix3d::Identity() + grad);
  EXPECT_LT((P - linear).norm(), 1e-4 * linear.norm());
}

INSTANTIATE_TEST_SUITE_P(Laws, Law, ::testing::ValuesIn(laws()), [](const auto& info) { return info.param.name; });

TEST(HyperelasticParameters, ConversionsAndErrors) {
  const HyperelasticLaw nh = neo_hookean_from_E_nu(3000, 0.45);
  EXPECT_NEAR(nh.youngs_modulus_pa(), 3000, 1e-9);
  EXPECT_NEAR(nh.poisson_ratio(), 0.45, 1e-12);
  const HyperelasticLaw mr = mooney_rivlin(400, 100, 1e6);
  EXPECT_NEAR(mr.shear_modulus_pa(), 2 * (400 + 100), 1e-9);  // μ₀ = 2(C10 + C01)
  EXPECT_THROW(neo_hookean_from_E_nu(3000, 0.5), Error);
  EXPECT_THROW(ogden({100}, {0}, 1e5), Error);
  EXPECT_THROW(ogden({100, 1, 2, 3}, {1, 2, 3, 4}, 1e5), Error);
}

// Drucker stability over tissue's range (uniaxial λ ∈ [0.5, 2], shear γ ∈ [0, 1]): the laws of the
// docs and tests are stable; C01 < 0 large against C10, or an Ogden term with μ·α < 0 that wins at
// large stretch, is not, and the place where the stress first stops rising is named.
TEST(HyperelasticParameters, StabilityOverTissueRange) {
  EXPECT_EQ(unstable_range(neo_hookean_from_E_nu(3000, 0.4999)), "");
  EXPECT_EQ(unstable_range(mooney_rivlin(8000, 2000, 1e6)), "");
  EXPECT_EQ(unstable_range(mooney_rivlin(1000, -100, 1e6)), "");  // mildly negative C01 holds
  EXPECT_EQ(unstable_range(ogden({1200, -300}, {4, -2}, 1e6)), "");
  EXPECT_EQ(unstable_range(mooney_rivlin(1000, -999.999, 1e6)), "in uniaxial stress at stretch 0.500");
  const std::string ogden_soft = unstable_range(ogden({3000, -500}, {2, 8}, 1e6));
  EXPECT_NE(ogden_soft.find("in uniaxial stress at stretch"), std::string::npos) << ogden_soft;
  // A small term of high order that wins only in tension (closed form: the stress peaks near 1.863)
  EXPECT_EQ(unstable_range(ogden({2000, -2}, {2, 10}, 1e6)), "in uniaxial stress at stretch 1.862");
}

}  // namespace
}  // namespace vb
