// Heun's corrector over the elements' blocks from the last to the first (engine/sim/
// correct_order.hpp; PlanOverrides::correct_reverse forces it here): each element's corrector is its
// own arithmetic, so the order must change no bit: springs with the general and the short loop
// (with the packed stage), with and without the volume constraint, and a hyperelastic law.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "engine/sim/correct_order.hpp"
#include "engine/sim/simulator.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

std::unique_ptr<Simulator> make(const Scene& s, const test::Model& m, bool reverse, bool short_loop) {
  PlanOverrides o = test::one_item_per_element();
  o.correct_reverse = reverse;
  o.uniform_path = short_loop;
  o.pred_packed = short_loop;
  o.step_list = false;
  return std::make_unique<Simulator>(s, m.lattice, m.elements, test::cl_context(), o);
}

/// u then v after 150 Heun steps, a check between runs of 15 and 135.
std::vector<double> run(const Scene& s, bool reverse, bool short_loop) {
  const test::Model m = test::make_model(s);
  const std::unique_ptr<Simulator> made = make(s, m, reverse, short_loop);
  Simulator& sim = *made;
  EXPECT_EQ(sim.correct_reverse(), reverse);
  sim.advance(15);
  EXPECT_EQ(sim.check().nonfinite_elements, 0);
  sim.advance(135);
  EXPECT_EQ(sim.check().nonfinite_elements, 0);
  return test::state_uv(sim);
}

TEST(CorrectOrder, ReverseBlocksChangeNoBit) {
  for (const bool volume : {false, true})
    for (const bool short_loop : {false, true}) {
      const Scene s = test::mixed_block(Integrator::Heun, volume);
      const std::vector<double> forward = run(s, false, short_loop), reverse = run(s, true, short_loop);
      ASSERT_EQ(forward.size(), reverse.size());
      EXPECT_EQ(test::differing_values(forward, reverse), 0u)
          << (volume ? "volume, " : "") << (short_loop ? "short loop, packed stage" : "general loop");
    }
}

TEST(CorrectOrder, ReverseBlocksChangeNoBitHyperelastic) {
  const Scene s = test::neo_hookean_mixed_block();
  EXPECT_EQ(test::differing_values(run(s, false, false), run(s, true, false)), 0u);
}

// Only Heun's one-work-item-per-element corrector: not with the list, nor for another integrator.
TEST(CorrectOrder, OnlyHeunsCorrectorInElementOrder) {
  const Scene heun = test::mixed_block(Integrator::Heun, false);
  const test::Model m = test::make_model(heun);
  {
    PlanOverrides o = test::one_item_per_element();
    o.step_list = true;
    o.correct_reverse = true;
    EXPECT_FALSE(Simulator(heun, m.lattice, m.elements, test::cl_context(), o).correct_reverse());
  }
  const Scene euler = test::mixed_block(Integrator::SymplecticEuler, false);
  const test::Model me = test::make_model(euler);
  EXPECT_FALSE(make(euler, me, true, false)->correct_reverse());
}

// On GPUs from 1,000,000 elements without the volume constraint (H200: linear cubes +4-5% at 1.0M
// and 1.5M, level at 512k, 3% slower at 262k; level with the constraint; docs/PERFORMANCE.md).
TEST(CorrectOrder, DefaultRule) {
  EXPECT_FALSE(default_correct_reverse(true, 512000, false));
  EXPECT_FALSE(default_correct_reverse(true, 999999, false));
  EXPECT_TRUE(default_correct_reverse(true, 1000000, false));
  EXPECT_TRUE(default_correct_reverse(true, 1520875, false));
  EXPECT_FALSE(default_correct_reverse(true, 1520875, true));
  EXPECT_FALSE(default_correct_reverse(false, 1520875, false));
}

}  // namespace
}  // namespace vb
