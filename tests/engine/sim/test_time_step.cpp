#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>

#include "engine/error.hpp"
#include "engine/sim/parallel_chunks.hpp"
#include "engine/sim/time_step.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

TEST(TimeStep, SymplecticEulerUndampedLimitIsTwoOverOmega) {
  StabilityBounds b{1000.0, 0.0};
  EXPECT_NEAR(stable_time_step(Integrator::SymplecticEuler, b, 0.0), 2.0 / 1000.0, 1e-9);
  EXPECT_NEAR(amplification(Integrator::SymplecticEuler, 1000.0, 0.0, 1.9e-3), 1.0, 1e-12);
  EXPECT_GT(amplification(Integrator::SymplecticEuler, 1000.0, 0.0, 2.1e-3), 1.0);
}

TEST(TimeStep, UndampedHeunGrowsAndDampedHeunIsStable) {
  EXPECT_GT(amplification(Integrator::Heun, 1000.0, 0.0, 1e-4), 1.0);  // RK2 has no imaginary-axis stability
  StabilityBounds damped{1000.0, 200.0};
  const double dt = stable_time_step(Integrator::Heun, damped, 0.0);
  EXPECT_GT(dt, 0.1 / 1000.0);
  EXPECT_LE(amplification(Integrator::Heun, 1000.0, 200.0, dt), 1.0 + 1e-9);
}

TEST(TimeStep, AutoStepIsBelowTheStableLimitAndRespondsToStiffness) {
  Scene s = test::box_scene(4, 4, 4, 0.002);
  s.solver.dashpot_ratio = 0.1;
  auto m = test::make_model(s);
  const TimeStepChoice soft = choose_time_step(s, m.lattice, m.elements);
  EXPECT_TRUE(soft.automatic);
  EXPECT_NEAR(soft.dt_s, s.solver.dt_safety * soft.stable_limit_s, 1e-15);
  s.materials["soft"].youngs_modulus_pa *= 4;
  m = test::make_model(s);
  const TimeStepChoice stiff = choose_time_step(s, m.lattice, m.elements);
  EXPECT_NEAR(stiff.dt_s / soft.dt_s, 0.5, 0.01);  // dt ∝ 1/√E
}

TEST(TimeStep, HeunWithoutDampingHasNoAutomaticStep) {
  Scene s = test::box_scene(3, 3, 3, 0.002);
  s.solver.dashpot_ratio = 0;
  s.solver.damping_per_s = 0;
  const auto m = test::make_model(s);
  EXPECT_THROW(choose_time_step(s, m.lattice, m.elements), Error);
}

// Relaxation walks the lattice once (the rows kept in its TimeStepChoice): its ω_max must be
// stability_bounds' without dashpots to the bit, and the mass scale made from the kept rows must
// put every free element's bound (k + penalty)/m̃ at ω_max², held ones at scale 1.
TEST(TimeStep, RelaxationBoundsAndMassScaleComeFromOneWalk) {
  Scene s = test::mixed_block(Integrator::Relaxation, false);  // two moduli, two masses, a held base
  const auto m = test::make_model(s);
  const TimeStepChoice relax = choose_time_step(s, m.lattice, m.elements);
  ASSERT_EQ(relax.row_stiffness_n_m.size(), m.lattice.element_count());
  EXPECT_EQ(relax.bounds.omega_max, stability_bounds(m.lattice, m.elements, 0, 0).omega_max);
  EXPECT_EQ(relax.bounds.damping_max, 0.0);
  EXPECT_EQ(relax.row_stiffness_n_m, element_row_stiffness_n_m(m.lattice, m.elements));

  std::vector<double> penalty(m.lattice.element_count());
  for (std::size_t e = 0; e < penalty.size(); ++e) penalty[e] = 50.0 * double(e % 7);
  const std::vector<double> scale = relaxation_mass_scale(m.elements, relax.row_stiffness_n_m, penalty);
  const double w2 = relax.bounds.omega_max * relax.bounds.omega_max;
  std::size_t held = 0;
  for (std::size_t e = 0; e < scale.size(); ++e) {
    const double im = m.elements.inverse_mass[e];
    if (im == 0) {
      EXPECT_EQ(scale[e], 1.0) << e;
      ++held;
      continue;
    }
    EXPECT_NEAR((relax.row_stiffness_n_m[e] + penalty[e]) * im * scale[e] / w2, 1.0, 1e-12) << e;
  }
  EXPECT_GT(held, 0u);
  EXPECT_EQ(relaxation_mass_scale(m.elements, relax.row_stiffness_n_m), relaxation_mass_scale(m.lattice, m.elements));
  s.solver.integrator = Integrator::Heun;
  s.solver.dashpot_ratio = 0.1;
  EXPECT_TRUE(choose_time_step(s, m.lattice, m.elements).row_stiffness_n_m.empty());
}

// Every index of [0, n) is visited once whatever the split, including more chunks than indices.
TEST(ParallelChunks, CoverEachIndexOnce) {
  for (const std::size_t n : {0u, 1u, 5u, 1000u, 65537u})
    for (const std::size_t chunks : {0u, 1u, 2u, 3u, 7u, 16u}) {  // 0: as 1
      std::vector<std::atomic<int>> seen(n);
      std::vector<int> chunk_of(n, -1);
      for_chunks(n, chunks, [&](std::size_t c, std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) ++seen[i], chunk_of[i] = int(c);
      });
      for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(seen[i].load(), 1) << "n " << n << ", chunks " << chunks << ", index " << i;
      EXPECT_TRUE(std::is_sorted(chunk_of.begin(), chunk_of.end())) << "chunks are contiguous, in order";
    }
  EXPECT_EQ(chunk_count(1000), 1u);  // too short to split
  EXPECT_LE(chunk_count(1u << 24), std::max(1u, std::thread::hardware_concurrency()));
}

// The walks over a model large enough to split (38,400 elements: two chunks or more on a 2-core
// machine): every element's row is computed (the interior's all equal, the faces' smaller, none
// left at zero), and the bound's walk agrees with the rows' walk on their largest.
TEST(TimeStep, WalksSplitOverCoresComputeEveryElementsRow) {
  const Scene s = test::box_scene(40, 40, 24, 0.002);
  const auto m = test::make_model(s);
  const std::size_t n = m.lattice.element_count();
  ASSERT_EQ(n, 38400u);
  ASSERT_GE(chunk_count(n), std::min(2u, std::max(1u, std::thread::hardware_concurrency())));
  const std::vector<double> k = element_row_stiffness_n_m(m.lattice, m.elements);
  ASSERT_EQ(k.size(), n);
  double interior = 0, most = 0;
  std::size_t interior_count = 0;
  for (std::size_t e = 0; e < n; ++e) {
    ASSERT_GT(k[e], 0.0) << "element " << e << " left out";
    most = std::max(most, k[e] * m.elements.inverse_mass[e]);
    const auto ijk = m.lattice.voxel_ijk(e);
    bool inside = true;
    for (int a = 0; a < 3; ++a) inside = inside && ijk[a] > 0 && ijk[a] + 1 < m.lattice.dims[a];
    if (!inside) continue;
    if (interior == 0) interior = k[e];
    EXPECT_EQ(k[e], interior) << e;
    ++interior_count;
  }
  EXPECT_EQ(interior_count, 38u * 38u * 22u);
  for (std::size_t e = 0; e < n; ++e) EXPECT_LE(k[e], interior) << e;
  EXPECT_EQ(stability_bounds(m.lattice, m.elements, 0, 0).omega_max, std::sqrt(most));
}

}  // namespace
}  // namespace vb
