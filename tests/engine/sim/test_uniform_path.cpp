// The short connection loop of linear springs for elements whose neighbours share their modulus
// and mass (kernels/lattice_forces.cl, lattice_force_uniform; engine/sim/uniform_neighbourhood.hpp;
// on by default on GPUs, PlanOverrides::uniform_path forces it here) against the general loop.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/sim/simulator.hpp"
#include "engine/sim/uniform_neighbourhood.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"
#include "tests/engine/sim/trajectory_compare.hpp"

namespace vb {
namespace {

// A 5×5×5 block: element (1,1,1) has another modulus, (3,3,3) is held. Marked: every free
// element whose 3×3×3 neighbourhood holds neither, also on the block's faces (missing neighbours
// do not count): 125 − 27 − 27 + 1 (the shared (2,2,2)) = 72.
TEST(UniformNeighbourhood, MarksElementsWhoseNeighboursShareModulusAndMass) {
  const test::Model m = test::make_model(test::box_scene(5, 5, 5, 0.004));
  const std::size_t n = m.lattice.element_count();
  ASSERT_EQ(n, 125u);
  const auto at = [&](std::size_t e, int c) {
    const auto ijk = m.lattice.voxel_ijk(e);
    return std::abs(ijk[0] - c) <= 1 && std::abs(ijk[1] - c) <= 1 && std::abs(ijk[2] - c) <= 1;
  };
  const auto is = [&](std::size_t e, int c) { return m.lattice.voxel_ijk(e) == std::array<int, 3>{c, c, c}; };
  std::vector<double> E(n, 3000), w(n, 0.5);
  for (std::size_t e = 0; e < n; ++e) {
    if (is(e, 1)) E[e] = 6000;
    if (is(e, 3)) w[e] = 0;
  }
  const std::vector<double> marked = mark_uniform_neighbourhoods(m.lattice, E, w);
  int count = 0;
  for (std::size_t e = 0; e < n; ++e) {
    EXPECT_EQ(marked[e], at(e, 1) || at(e, 3) ? E[e] : -E[e]) << e;
    count += marked[e] < 0;
  }
  EXPECT_EQ(count, 72);

  // In aligned blocks of 8 indices (a GPU's lockstep group): a block's free elements are marked
  // together or not at all; the held element is never marked.
  const std::size_t lockstep = 8;
  const std::vector<double> grouped = mark_uniform_neighbourhoods(m.lattice, E, w, lockstep);
  int grouped_count = 0;
  for (std::size_t first = 0; first < n; first += lockstep) {
    bool all = true;
    for (std::size_t e = first; e < std::min(n, first + lockstep); ++e)
      if (w[e] != 0 && marked[e] > 0) all = false;
    for (std::size_t e = first; e < std::min(n, first + lockstep); ++e) {
      EXPECT_EQ(grouped[e], all && w[e] != 0 ? -E[e] : E[e]) << e;
      grouped_count += grouped[e] < 0;
    }
  }
  EXPECT_GT(grouped_count, 0);
  EXPECT_LT(grouped_count, count);  // blocks that mix the two kinds lose their marks
}

/// A simulator of model m with the short loop on or off and Heun's predicted stage packed (1),
/// not (0) or by default (-1); neither the one-launch step (GPUs) nor the lanes kernels (CPUs,
/// float) have the short loop, so both are off.
std::unique_ptr<Simulator> make_simulator(const Scene& s, const test::Model& m, bool uniform, int packed) {
  PlanOverrides o = test::one_item_per_element();
  o.uniform_path = uniform;
  if (packed >= 0) o.pred_packed = packed == 1;
  return std::make_unique<Simulator>(s, m.lattice, m.elements, test::cl_context(), o);
}

/// u then v after 300 steps from rest (checks every 100: relaxation sets its damping there).
/// `packed`: as make_simulator's, and when asked for, expected.
std::vector<double> run(const Scene& s, bool uniform, int packed = -1) {
  const test::Model m = test::make_model(s);
  const std::unique_ptr<Simulator> made = make_simulator(s, m, uniform, packed);
  Simulator& sim = *made;
  EXPECT_EQ(sim.uniform_path(), uniform);
  if (packed >= 0) EXPECT_EQ(sim.pred_packed(), packed == 1);
  // Enough elements on each loop for the comparison to mean something: marked one by one (CPUs)
  // most of the block's free elements, not those next to the inclusion, the heavy layer or the
  // base; in whole warps of 32 (NVIDIA) fewer, 138 of 810.
  const bool per_element = test::cl_context().info.simd_width == 1;
  if (uniform) EXPECT_GT(sim.uniform_elements(), m.lattice.element_count() / (per_element ? 5 : 8));
  if (uniform) EXPECT_LT(sim.uniform_elements(), m.lattice.element_count() * 4 / 5);
  if (!uniform) EXPECT_EQ(sim.uniform_elements(), 0u);
  for (int k = 0; k < 3; ++k) {
    sim.advance(100);
    EXPECT_EQ(sim.check().nonfinite_elements, 0);
  }
  return test::state_uv(sim);
}

// In double the two loops differ only in rounding (κ·h·E against the harmonic mean 2E²/(2E),
// one square root per element against one per connection): 1e-13 of the motion here. A marked
// element next to the inclusion would see a spring 1.5× too soft, next to the heavy layer or
// the base a dashpot 8–40% off.
TEST(UniformPath, MatchesTheGeneralLoop) {
  for (const Integrator integrator : {Integrator::Heun, Integrator::SymplecticEuler, Integrator::Relaxation})
    for (const bool volume : {false, true}) {
      const Scene s = test::mixed_block(integrator, volume);
      const double d = test::relative_difference(run(s, true), run(s, false));
      std::cout << "integrator " << int(integrator) << (volume ? ", volume" : "") << ": short vs general loop " << d << "\n";
      EXPECT_LE(d, 1e-11);
    }
}

// Heun's predicted stage packed (kernels/lattice_forces.cl, stage_load; by default on GPUs with
// the short loop): the same values read from other addresses, so the same trajectory to the last
// bit in both precisions. The block's general-loop elements (next to the inclusion, the heavy
// layer and the base) read their neighbours' inverse mass from the state instead of the stage.
TEST(UniformPath, PackedPredictedStageChangesNoBit) {
  for (const Precision precision : {Precision::Float, Precision::Double}) {
    Scene s = test::mixed_block(Integrator::Heun, false);
    s.solver.precision = precision;
    const std::vector<double> packed = run(s, true, 1), plain = run(s, true, 0);
    ASSERT_EQ(packed.size(), plain.size());
    double moved = 0;  // the block sags under gravity: the comparison is of a motion
    for (double x : plain) moved = std::max(moved, std::abs(x));
    EXPECT_GT(moved, 1e-5);
    EXPECT_EQ(test::differing_values(packed, plain), 0u) << (precision == Precision::Float ? "float" : "double");
  }
}

// Nor where anything but the corrector reads the stage: the volume constraint (its projection of
// the predicted stage), the short loop off (the general loop alone), other integrators.
TEST(UniformPath, PredictedStageStaysUnpackedWhereOthersReadIt) {
  const auto packed = [](const Scene& s, bool uniform) {
    const test::Model m = test::make_model(s);
    return make_simulator(s, m, uniform, 1)->pred_packed();
  };
  EXPECT_TRUE(packed(test::mixed_block(Integrator::Heun, false), true));
  EXPECT_FALSE(packed(test::mixed_block(Integrator::Heun, true), true));
  EXPECT_FALSE(packed(test::mixed_block(Integrator::Heun, false), false));
  EXPECT_FALSE(packed(test::mixed_block(Integrator::SymplecticEuler, false), true));
}

// By default on GPUs where the short loop takes at least half the free elements (the cubes, not
// the phantom, whose tissue interfaces leave it almost none in whole warps).
TEST(UniformPath, PredictedStagePackedByDefaultWhereTheShortLoopTakesHalf) {
  EXPECT_TRUE(default_pred_packing(true, 50, 100));
  EXPECT_TRUE(default_pred_packing(true, 1507650, 1507650));
  EXPECT_FALSE(default_pred_packing(true, 49, 100));
  EXPECT_FALSE(default_pred_packing(true, 0, 20969));
  EXPECT_FALSE(default_pred_packing(false, 100, 100));
}

}  // namespace
}  // namespace vb
