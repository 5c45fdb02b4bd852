#include "engine/fit/material_scaling.hpp"

#include "engine/fit/initial_guess.hpp"

namespace vb {

MaterialSpec material_with_modulus(const MaterialSpec& m, double E) {
  MaterialSpec out = m;
  if (!m.hyperelastic()) {
    out.youngs_modulus_pa = E;
    return out;
  }
  // W is linear in (μ_p, κ) at fixed α_p: scaling them all scales every stress, and so the
  // small-strain E, by s.
  const double s = E / material_modulus_pa(m);
  out.youngs_modulus_pa *= s;  // neo-Hookean's μ (and κ when derived from ν)
  out.bulk_modulus_pa *= s;    // 0 (derived from μ₀ and ν) stays 0
  out.c10_pa *= s;
  out.c01_pa *= s;
  for (double& mu : out.ogden_mu_pa) mu *= s;
  return out;
}

}  // namespace vb
