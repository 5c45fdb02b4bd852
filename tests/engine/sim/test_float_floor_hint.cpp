#include <gtest/gtest.h>

#include "engine/sim/run.hpp"

namespace vb {
namespace {

// What the phantom's tightest ring at 1e-6 gave before push contact took distances within float's
// resolution as zero (docs/VALIDATION.md, "Contact inside the band"): Heun in float stopped at
// max_steps 60,000 with its residual at 2.3e-7 and its speed at 1.46e-6 of the wave speed.
RunSummary ring_run_at_max_steps() {
  RunSummary s;
  s.converged = false;
  s.stop_reason = "max_steps";
  s.final_residual = 2.3e-7;
  s.final_speed_ratio = 1.46e-6;
  return s;
}

Scene float_heun_scene(double tol) {
  Scene scene;
  scene.solver.precision = Precision::Float;
  scene.solver.integrator = Integrator::Heun;
  scene.stop.equilibrium = tol;
  return scene;
}

TEST(FloatFloorHint, NamesDoublePrecisionWhenOnlyTheSpeedMissedATightTolerance) {
  const auto hint = float_floor_hint(float_heun_scene(1e-6), ring_run_at_max_steps());
  ASSERT_TRUE(hint.has_value());
  EXPECT_NE(hint->find("solver.precision = \"double\""), std::string::npos) << *hint;
  EXPECT_NE(hint->find("1.5e-06"), std::string::npos) << *hint;  // the speed it stopped at
}

TEST(FloatFloorHint, SaysNothingWhereRoundOffIsNotTheReason) {
  const RunSummary ring = ring_run_at_max_steps();
  EXPECT_FALSE(float_floor_hint(float_heun_scene(1e-5), ring)) << "a tolerance well above float's floor";
  Scene d = float_heun_scene(1e-6);
  d.solver.precision = Precision::Double;
  EXPECT_FALSE(float_floor_hint(d, ring)) << "already double";
  Scene r = float_heun_scene(1e-6);
  r.solver.integrator = Integrator::Relaxation;
  EXPECT_FALSE(float_floor_hint(r, ring)) << "relaxation's speed criterion is another";
  RunSummary residual = ring;
  residual.final_residual = 5e-6;
  EXPECT_FALSE(float_floor_hint(float_heun_scene(1e-6), residual)) << "the residual missed too";
  RunSummary timed = ring;
  timed.stop_reason = "max_time";
  EXPECT_FALSE(float_floor_hint(float_heun_scene(1e-6), timed)) << "a run cut by its simulated time";
  RunSummary settled = ring;
  settled.converged = true;
  settled.stop_reason = "equilibrium";
  EXPECT_FALSE(float_floor_hint(float_heun_scene(1e-6), settled));
}

}  // namespace
}  // namespace vb
