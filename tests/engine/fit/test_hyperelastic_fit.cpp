// Hyperelastic fitting (docs/FIT.md, "Hyperelastic tissues"): one modulus scale per region; the
// law's shape is kept and its small-strain E is what the fit reports. An Ogden and a
// Mooney-Rivlin inclusion's modulus is recovered from a noise-free observation made by the
// hyperelastic forward model itself.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/fit/fit_data.hpp"
#include "engine/fit/gauss_newton.hpp"
#include "engine/fit/initial_guess.hpp"
#include "engine/fit/material_scaling.hpp"
#include "engine/material/hyperelastic.hpp"
#include "tests/engine/fit/fit_fixtures.hpp"

namespace vb {
namespace {

MaterialSpec ogden_material(const std::string& name) {  // two terms, μ₀ = 5.4 kPa, ν = 0.45
  MaterialSpec m = test::material(name, 0);
  m.law = "ogden";
  m.ogden_mu_pa = {2400, -600};
  m.ogden_alpha = {4, -2};
  m.poisson_ratio = 0.45;
  return m;
}

MaterialSpec mooney_rivlin_material(const std::string& name) {  // C01/C10 = 1/4, explicit κ
  MaterialSpec m = test::material(name, 0);
  m.law = "mooney-rivlin";
  m.c10_pa = 2000;
  m.c01_pa = 500;
  m.bulk_modulus_pa = 50000;
  return m;
}

TEST(HyperelasticScaling, KeepsTheLawsShapeAndSetsItsSmallStrainModulus) {
  for (const MaterialSpec& m : {ogden_material("t"), mooney_rivlin_material("t")}) {
    const double E0 = material_modulus_pa(m);
    EXPECT_NEAR(E0, law_of(m).youngs_modulus_pa(), 1e-9 * E0);
    const MaterialSpec scaled = material_with_modulus(m, 2.5 * E0);
    const HyperelasticLaw a = law_of(m), b = law_of(scaled);
    EXPECT_NEAR(b.youngs_modulus_pa(), 2.5 * E0, 1e-9 * E0) << m.law;
    EXPECT_NEAR(b.poisson_ratio(), a.poisson_ratio(), 1e-12) << m.law;
    for (int p = 0; p < a.terms; ++p) {
      EXPECT_DOUBLE_EQ(b.alpha[p], a.alpha[p]);
      EXPECT_NEAR(b.mu_pa[p], 2.5 * a.mu_pa[p], 1e-9 * std::abs(a.mu_pa[p]));
    }
    // Every stress scales with the constants: the stretched response keeps its shape.
    EXPECT_NEAR(uniaxial_nominal_stress(b, 1.3), 2.5 * uniaxial_nominal_stress(a, 1.3),
                1e-9 * std::abs(uniaxial_nominal_stress(a, 1.3)));
  }
  MaterialSpec nh = test::material("t", 4000);
  nh.law = "neo-hookean";
  EXPECT_DOUBLE_EQ(material_modulus_pa(nh), 4000);
  EXPECT_DOUBLE_EQ(material_with_modulus(nh, 6000).youngs_modulus_pa, 6000);
}

struct LawCase {
  std::string name;
  MaterialSpec tumour;
  int batch;  ///< fit.batch: the Ogden fit takes its Jacobians batched, the Mooney-Rivlin one not
};

class HyperelasticFit : public ::testing::TestWithParam<LawCase> {};

TEST_P(HyperelasticFit, RecoversTheInclusionsModulus) {
  MaterialSpec soft = test::material("soft", 3000);
  soft.law = "neo-hookean";
  soft.poisson_ratio = 0.45;
  const Scene s = test::fit_box_scene(soft, GetParam().tumour);
  const Lattice lattice = build_lattice(voxelise_shapes(s));
  FitSpec f = test::fit_box_spec();
  f.batch = GetParam().batch;
  const FitRegions regions = make_fit_regions(f, s, lattice);
  const ForwardModel model(s, lattice, regions, f, test::cl_context());
  const std::vector<double> truth = moduli_from_materials(s, lattice, regions);  // soft, tumour
  ASSERT_EQ(regions.names[1], "tumour");
  EXPECT_NEAR(truth[1], law_of(GetParam().tumour).youngs_modulus_pa(), 1e-6 * truth[1]);

  // Noise-free observation: the truth's displacement at every free element, σ = 1 mm.
  Observation obs;
  obs.displacement_m = model.solve(truth).change_m();
  const ElementArrays el = make_element_arrays(s, lattice);
  obs.weight_per_m2.resize(lattice.element_count());
  for (std::size_t e = 0; e < lattice.element_count(); ++e) obs.weight_per_m2[e] = el.inverse_mass[e] > 0 ? 1e6 : 0;

  const DisplacementData data(obs);
  FitProblem p;
  p.model = &model;
  p.data = &data;
  p.observation = &obs;
  p.initial_pa = {0.7 * truth[0], 0.4 * truth[1]};  // 30% too soft, the inclusion 2.5× too soft
  p.min_pa = 500;
  p.max_pa = 200000;
  p.spec = f;
  const FitProgress out = run_gauss_newton(p, FitProgress{}, nullptr);
  const double error = out.modulus_pa[1] / truth[1] - 1;
  std::cout << GetParam().name << " inclusion: truth " << truth[1] << " Pa, recovered " << out.modulus_pa[1]
            << " Pa (" << 100 * error << "%), soft " << 100 * (out.modulus_pa[0] / truth[0] - 1) << "%; within 1 mm "
            << out.history.back().within_1mm << ", RMS " << out.history.back().rms_mm << " mm, "
            << out.history.size() - 1 << " iterations, " << model.forward_solves() << " solves (" << out.stop_reason
            << ")\n";
  EXPECT_LT(std::abs(error), 0.10) << GetParam().name;
  EXPECT_LT(std::abs(out.modulus_pa[0] / truth[0] - 1), 0.02) << GetParam().name;
  EXPECT_GE(out.history.back().within_1mm, 0.99);
  EXPECT_LT(out.history.back().rms_mm, 0.1 * out.history.front().rms_mm);
}

INSTANTIATE_TEST_SUITE_P(Laws, HyperelasticFit,
                         ::testing::Values(LawCase{"ogden", ogden_material("tumour"), 2},
                                           LawCase{"mooney_rivlin", mooney_rivlin_material("tumour"), 1}),
                         [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace vb
