#include <gtest/gtest.h>

#include <Eigen/Core>

#include "engine/lattice/lattice.hpp"
#include "engine/material/linear_spring.hpp"

namespace vb {
namespace {

/// Small-strain elasticity tensor of the interior lattice, C_ijkl = (1/h³)·Σ_unique k·L²·n_i n_j n_k n_l.
double lattice_C(int i, int j, int k, int l, double E, double h) {
  double c = 0;
  for (int d = 0; d < 26; ++d) {
    const auto& o = neighbour_offsets()[d];
    const Eigen::Vector3d n = Eigen::Vector3d(o[0], o[1], o[2]).normalized();
    const double L = h * linear_spring::rest_length_factor(d);
    c += 0.5 * linear_spring::kappa(d) * E * h * L * L * n[i] * n[j] * n[k] * n[l];  // ½: each pair twice
  }
  return c / (h * h * h);
}

TEST(LinearSpring, InteriorLatticeIsIsotropicWithRequestedModulus) {
  const double E = 4321.0, h = 0.003;
  const double C11 = lattice_C(0, 0, 0, 0, E, h), C12 = lattice_C(0, 0, 1, 1, E, h), C44 = lattice_C(0, 1, 0, 1, E, h);
  EXPECT_NEAR(C11 - C12, 2 * C44, 1e-9 * E) << "isotropy";
  const double mu = C44, lambda = C12;
  const double E_eff = mu * (3 * lambda + 2 * mu) / (lambda + mu);
  const double nu_eff = lambda / (2 * (lambda + mu));
  EXPECT_NEAR(E_eff / E, 1.0, 1e-12);
  EXPECT_NEAR(nu_eff, linear_spring::poisson_ratio, 1e-12);
}

}  // namespace
}  // namespace vb
