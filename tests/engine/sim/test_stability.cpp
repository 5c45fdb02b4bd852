// Blow-up is detected within a bounded number of steps and reported with step, element and a
// smaller-dt hint; it is never silently returned as a result.
#include <gtest/gtest.h>

#include "engine/error.hpp"
#include "engine/sim/run.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

TEST(Stability, TooLargeTimeStepIsDetectedAndReported) {
  Scene s = test::box_scene(6, 6, 6, 0.002);
  s.anchors.push_back(test::halfspace_anchor("base", Vec3(0, 0, 0.002), Vec3(0, 0, -1)));
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -9.81);
  s.solver.integrator = Integrator::SymplecticEuler;
  s.solver.dashpot_ratio = 0;
  s.solver.check_every = 50;
  s.stop.max_steps = 100000;
  auto m = test::make_model(s);
  s.solver.dt_s = 1.0;  // placeholder, replaced below by 3× the stable limit
  {
    Simulator probe(s, m.lattice, m.elements, test::cl_context());
    s.solver.dt_s = 3.0 * probe.time_step().stable_limit_s;
  }
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  try {
    run_simulation(s, m.lattice, m.elements, sim);
    FAIL() << "expected the instability to be reported";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("unstable at step"), std::string::npos) << msg;
    EXPECT_NE(msg.find("element"), std::string::npos) << msg;
    EXPECT_NE(msg.find("smaller solver.dt"), std::string::npos) << msg;
  }
  EXPECT_LE(sim.steps(), 2000) << "detection must come within a bounded number of steps";
}

}  // namespace
}  // namespace vb
