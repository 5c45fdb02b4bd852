// Simulator::set_materials: a simulator given new moduli must step exactly as one built anew with
// them (the fit keeps one simulator across its solves, engine/fit/forward_model.cpp).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "engine/error.hpp"
#include "engine/fit/initial_guess.hpp"
#include "engine/fit/material_scaling.hpp"
#include "engine/sim/simulator.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

using test::cl_context;

struct Case {
  const char* name;
  Integrator integrator;
  const char* law;  ///< of every tissue
  bool volume;
  Precision precision;
  bool indenter = false;  ///< a plate pressing on the top
};

std::string case_name(const ::testing::TestParamInfo<Case>& info) { return info.param.name; }

Scene case_scene(const Case& c) {
  Scene s = test::mixed_block(c.integrator, c.volume);
  s.solver.precision = c.precision;
  for (auto& [name, m] : s.materials) {
    m.law = c.law;
    if (m.law == std::string("biphasic")) m.cubic = 200, m.critical_strain = 0.02;
    if (m.law == std::string("ogden")) {  // the validation law's shape at the tissue's E
      MaterialSpec ogden = test::validation_material("ogden", 0.45);
      ogden.name = m.name;
      ogden.density_kg_m3 = m.density_kg_m3;
      m = material_with_modulus(ogden, m.youngs_modulus_pa);
    }
  }
  if (c.indenter) s.indenters.push_back(test::plate_pair(10, 0.004, 0.97)[1]);
  return s;
}

/// The scene with each tissue's small-strain modulus scaled (one factor per tissue, in name order).
Scene with_moduli(Scene s, const std::vector<double>& factor) {
  std::size_t i = 0;
  for (auto& [name, m] : s.materials) {
    const double f = factor[i++ % factor.size()];
    m = material_with_modulus(m, f * material_modulus_pa(m));
  }
  return s;
}

struct Stepped {
  std::vector<double> uv;
  double dt_s = 0;
  std::vector<double> residual;  ///< residual ratio at each check
};

/// 3 rounds of 40 steps with a check after each (relaxation adapts its damping there)
Stepped step(Simulator& sim) {
  Stepped out;
  for (int round = 0; round < 3; ++round) {
    sim.advance(40);
    out.residual.push_back(sim.check().residual_ratio);
  }
  out.uv = test::state_uv(sim);
  out.dt_s = sim.dt_s();
  return out;
}

class SetMaterials : public ::testing::TestWithParam<Case> {};

TEST_P(SetMaterials, StepsExactlyAsASimulatorBuiltWithTheNewModuli) {
  const Scene base = case_scene(GetParam());
  const Lattice lattice = test::make_model(base).lattice;
  const std::vector<std::vector<double>> moduli = {{1.0}, {0.5, 2.0, 1.3}, {3.0, 0.7, 0.4}, {1.0}};
  std::vector<Scene> scenes;
  for (const auto& f : moduli) scenes.push_back(with_moduli(base, f));

  Simulator kept(base, lattice, make_element_arrays(base, lattice), cl_context());
  step(kept);  // a used simulator: state, clock and relaxation's estimate all moved
  kept.set_gravity(Vec3(0, 9.81, 0));  // set_materials puts the scene's gravity and indenters back
  if (GetParam().indenter) kept.place_indenter(0, Vec3(0, 0, 0.01));
  Stepped prev;
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    SCOPED_TRACE("moduli set " + std::to_string(k));
    const ElementArrays el = make_element_arrays(scenes[k], lattice);
    kept.set_materials(el);
    EXPECT_EQ(kept.steps(), 0);
    const Stepped a = step(kept);
    Simulator fresh(scenes[k], lattice, el, cl_context());
    const Stepped b = step(fresh);
    EXPECT_EQ(a.dt_s, b.dt_s);
    EXPECT_EQ(a.residual, b.residual);
    EXPECT_EQ(test::differing_values(a.uv, b.uv), 0u) << "of " << a.uv.size() << " values";
    if (k > 0) EXPECT_NE(a.uv, prev.uv) << "the moduli did not change the motion: the comparison could not see them";
    prev = a;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Integrators, SetMaterials,
    ::testing::Values(Case{"RelaxationLinear", Integrator::Relaxation, "linear", false, Precision::Double},
                      Case{"RelaxationNeoHookeanFloat", Integrator::Relaxation, "neo-hookean", false, Precision::Float},
                      Case{"RelaxationLinearVolume", Integrator::Relaxation, "linear", true, Precision::Double},
                      Case{"HeunLinearFloat", Integrator::Heun, "linear", false, Precision::Float},
                      Case{"HeunLinearPlate", Integrator::Heun, "linear", false, Precision::Double, true},
                      Case{"HeunOgdenVolume", Integrator::Heun, "ogden", true, Precision::Double},
                      Case{"EulerBiphasic", Integrator::SymplecticEuler, "biphasic", false, Precision::Double}),
    case_name);

TEST(SetMaterials, OtherMassesOrLawsAreRefused) {
  const Scene base = case_scene({"", Integrator::Relaxation, "linear", false, Precision::Double});
  const Lattice lattice = test::make_model(base).lattice;
  Simulator sim(base, lattice, make_element_arrays(base, lattice), cl_context());
  Scene denser = base;
  denser.materials["soft"].density_kg_m3 *= 2;
  EXPECT_THROW(sim.set_materials(make_element_arrays(denser, lattice)), Error);
  Scene biphasic = base;
  for (auto& [name, m] : biphasic.materials) m.law = "biphasic", m.cubic = 200, m.critical_strain = 0.02;
  EXPECT_THROW(sim.set_materials(make_element_arrays(biphasic, lattice)), Error);
  ElementArrays short_el = make_element_arrays(base, lattice);
  short_el.youngs_modulus_pa.pop_back();
  EXPECT_THROW(sim.set_materials(short_el), Error);
}

}  // namespace
}  // namespace vb
