// The stepping kernels over a list of the free elements (kernels/common.cl, VB_STEP_LIST; on by
// default on GPUs for large models with a quarter or more held, engine/sim/step_list_rule.hpp;
// PlanOverrides::step_list forces it here) against the same kernels over every element: each
// element's arithmetic is the same, so the two must agree to the bit, also after the host moves
// the held elements (their copy in the predicted-stage arrays is the host's to keep).
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "engine/sim/simulator.hpp"
#include "engine/sim/step_list_rule.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

/// u then v after 200 steps, the held base shifted by 0.3 mm along x by the host after the first
/// 100 (as a moved anchor would be).
std::vector<double> run(const Scene& s, bool listed) {
  const test::Model m = test::make_model(s);
  const std::unique_ptr<Simulator> made = [&] {
    PlanOverrides o = test::one_item_per_element();  // the real4 kernels, which the list is for
    o.step_list = listed;
    // the same connection loop in both (GPUs: the short loop is off by default with the list)
    o.uniform_path = false;
    return std::make_unique<Simulator>(s, m.lattice, m.elements, test::cl_context(), o);
  }();
  Simulator& sim = *made;
  EXPECT_EQ(sim.step_list(), listed);
  sim.advance(100);
  std::vector<double> u, v;
  sim.download(u, v);
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e)
    if (m.elements.inverse_mass[e] == 0) u[3 * e] += 3e-4;
  sim.upload(u, v);
  sim.advance(100);
  EXPECT_EQ(sim.check().nonfinite_elements, 0);
  return test::state_uv(sim);
}

TEST(StepList, MatchesEveryElementsLaunchToTheBit) {
  for (const Integrator integrator : {Integrator::Heun, Integrator::SymplecticEuler, Integrator::Relaxation})
    for (const bool volume : {false, true}) {
      const Scene s = test::mixed_block(integrator, volume);
      const std::vector<double> all = run(s, false), listed = run(s, true);
      ASSERT_EQ(all.size(), listed.size());
      EXPECT_EQ(test::differing_values(all, listed), 0u) << "integrator " << int(integrator) << (volume ? ", volume" : "");
    }
}

// The default rule: GPUs only, a quarter or more held, above 65,536 elements, and above 81,920
// for hyperelastic relaxation (which lost 1–8% on the list from 56k to 76k on the H200).
TEST(StepList, DefaultRuleTakesLargeGpuModelsWithAQuarterHeld) {
  EXPECT_FALSE(default_step_list(true, 65536, 40000, false));
  EXPECT_TRUE(default_step_list(true, 65537, 40000, false));
  EXPECT_FALSE(default_step_list(false, 1500000, 1000000, false));  // CPUs: the lanes kernels' own list
  EXPECT_FALSE(default_step_list(true, 1500000, 374999, false));    // fewer than a quarter held
  EXPECT_TRUE(default_step_list(true, 1500000, 375000, false));
  EXPECT_FALSE(default_step_list(true, 76000, 50000, true));
  EXPECT_FALSE(default_step_list(true, 81920, 50000, true));
  EXPECT_TRUE(default_step_list(true, 81921, 50000, true));

  // A small model is not listed by default on any device.
  const Scene s = test::mixed_block(Integrator::Heun, false);
  const test::Model m = test::make_model(s);
  const Simulator sim(s, m.lattice, m.elements, test::cl_context());
  EXPECT_FALSE(sim.step_list());
}

}  // namespace
}  // namespace vb
