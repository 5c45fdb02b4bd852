// The stepping kernels' work-group size (engine/sim/step_work_group.hpp; PlanOverrides::step_work_group
// forces it here): each element's arithmetic does not depend on which group steps it, so groups of 32 and
// 256 must agree to the bit, with and without the step list and the volume constraint, for every
// integrator, springs and a hyperelastic law.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "engine/error.hpp"
#include "engine/sim/simulator.hpp"
#include "engine/sim/step_work_group.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

/// u then v after 150 steps with the stepping kernels in groups of `wg` work-items.
std::vector<double> run(const Scene& s, std::size_t wg, bool listed) {
  const test::Model m = test::make_model(s);
  PlanOverrides o = test::one_item_per_element();
  o.step_work_group = wg;
  o.step_list = listed;
  const auto made = std::make_unique<Simulator>(s, m.lattice, m.elements, test::cl_context(), o);
  Simulator& sim = *made;
  EXPECT_EQ(sim.step_work_group(), wg);
  EXPECT_EQ(sim.step_list(), listed);
  sim.advance(150);
  EXPECT_EQ(sim.check().nonfinite_elements, 0);
  return test::state_uv(sim);
}

TEST(StepWorkGroup, GroupSizeChangesNoBit) {
  for (const Integrator integrator : {Integrator::Heun, Integrator::SymplecticEuler, Integrator::Relaxation})
    for (const bool volume : {false, true})
      for (const bool listed : {false, true}) {
        const Scene s = test::mixed_block(integrator, volume);
        const std::vector<double> small = run(s, 32, listed), large = run(s, 256, listed);
        EXPECT_EQ(test::differing_values(small, large), 0u)
            << "integrator " << int(integrator) << (volume ? ", volume" : "") << (listed ? ", list" : "");
      }
}

TEST(StepWorkGroup, GroupSizeChangesNoBitHyperelastic) {
  const Scene s = test::neo_hookean_mixed_block();
  EXPECT_EQ(test::differing_values(run(s, 32, false), run(s, 256, false)), 0u);
}

// 256 from 131,072 elements (H200: 2–12% from 262k up, level below; docs/PERFORMANCE.md).
TEST(StepWorkGroup, DefaultRuleTakesLargerGroupsForLargeModels) {
  EXPECT_EQ(default_step_work_group(36000), 128u);
  EXPECT_EQ(default_step_work_group(131071), 128u);
  EXPECT_EQ(default_step_work_group(131072), 256u);
  EXPECT_EQ(default_step_work_group(1520875), 256u);
}

TEST(StepWorkGroup, OverrideNamesTheLimits) {
  EXPECT_EQ(checked_step_work_group(64, 1024), 64u);
  EXPECT_EQ(checked_step_work_group(1024, 1024), 1024u);
  for (const std::size_t bad : {100, 0, 16, 2048, 250}) {
    try {
      checked_step_work_group(bad, 1024);
      ADD_FAILURE() << "accepted " << bad;
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("step_work_group"), std::string::npos) << what;
      EXPECT_NE(what.find("multiple of 32"), std::string::npos) << what;
      EXPECT_NE(what.find("1024"), std::string::npos) << what;
    }
  }
}

TEST(StepWorkGroup, SimulatorRefusesABadOverride) {
  const Scene s = test::mixed_block(Integrator::Heun, false);
  const test::Model m = test::make_model(s);
  PlanOverrides o = test::one_item_per_element();
  o.step_work_group = 48;
  EXPECT_THROW(Simulator(s, m.lattice, m.elements, test::cl_context(), o), Error);
}

}  // namespace
}  // namespace vb
