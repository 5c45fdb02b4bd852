#include <gtest/gtest.h>

#include "engine/error.hpp"
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

}  // namespace
}  // namespace vb
