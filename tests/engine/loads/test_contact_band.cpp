// Push contact at rest just off an obstacle (a torus tube, a sphere indenter), on the OpenCL
// kernels (PoCL in CI). An element counts as touching within 10⁻³·h of an obstacle's surface (the
// contact band). When its free equilibrium lies inside the band, it must settle there, free:
// before each stage kept the inward force that only brings an element onto the surface, the
// obstacle took its restoring force away within the band, so it coasted out to the band's edge,
// fell back onto the surface and cycled. Heun ran both cases below to max_steps (27 nm and 0.23 µm off),
// relaxation stopped 0.7 µm off over the sphere, and the device sample's tightest front ring
// under relaxation ran to max_steps (docs/PHYSICS.md, "Indenters" and "Torus device").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <tuple>

#include "engine/sim/run.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

constexpr double g = 9.81, h = 0.002;
constexpr double kGap = 0.5e-3 * h;  // under the free equilibrium: half the band

enum class Obstacle { Torus, Sphere };

struct HangingRun {
  RunOutput out;
  double bottom_z = 0;  ///< the bottom-centre element's height at the end (m)
};

/// A 6 × 6 × 6 mm block (2 mm elements) hanging from its held top layer under gravity. Under its
/// bottom-centre element an obstacle whose top starts just under the element's rest position and
/// comes down to `top_z` in 0.1 s, so the element rides down on it (no obstacle: top_z infinite).
/// The torus: R = 5 mm, r = 3 mm, axis z, shrinking; the sphere: radius 3 mm, moving down.
HangingRun hang_over(Obstacle obstacle, Integrator integrator, double top_z) {
  Scene s = test::box_scene(3, 3, 3, h, 3000);
  s.anchors.push_back(test::halfspace_anchor("top", Vec3(0, 0, 0.004), Vec3::UnitZ()));
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -g);
  const double start_top = 0.001 - kGap, r = 0.003, time = 0.1;
  if (std::isfinite(top_z) && obstacle == Obstacle::Torus) {
    TorusSpec t;
    t.name = "ring";
    t.center_m = Vec3(0.003 - 0.005, 0.003, top_z - r);
    t.axis = Vec3::UnitZ();
    t.schedule = {{0.0, r + start_top - top_z, 0.005}, {time, r, 0.005}};
    s.tori.push_back(t);
  }
  if (std::isfinite(top_z) && obstacle == Obstacle::Sphere) {
    IndenterSpec b;
    b.kind = IndenterSpec::Kind::Sphere;
    b.radius_m = r;
    b.start_m = Vec3(0.003, 0.003, start_top - r);
    b.velocity_m_s = Vec3(0, 0, (top_z - start_top) / time);
    b.travel_time_s = time;
    s.indenters.push_back(b);
  }
  s.solver.integrator = integrator;
  s.solver.precision = Precision::Double;
  s.solver.damping_per_s = 30;
  s.solver.dashpot_ratio = 0.1;
  s.stop.equilibrium = 1e-7;
  s.stop.max_steps = 50000;
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  HangingRun run;
  run.out = run_simulation(s, m.lattice, m.elements, sim);
  run.bottom_z = run.out.state.position_m[3 * nearest_element(m.lattice, Vec3(0.003, 0.003, 0.001)) + 2];
  return run;
}

class ContactBand : public ::testing::TestWithParam<std::tuple<Obstacle, Integrator>> {};

TEST_P(ContactBand, FreeEquilibriumInsideTheBandSettlesFree) {
  const auto [obstacle, integrator] = GetParam();
  const HangingRun free = hang_over(obstacle, integrator, INFINITY);
  ASSERT_TRUE(free.out.summary.converged) << free.out.summary.stop_reason;
  const HangingRun over = hang_over(obstacle, integrator, free.bottom_z - kGap);
  const RunSummary& s = over.out.summary;
  const Vec3 carried = obstacle == Obstacle::Torus ? s.tori.at(0).force_n : s.indenters.at(0).reaction_force_n;
  std::printf("bottom element free at z = %.9f mm, over the obstacle %.9f mm (%s after %lld steps, free %lld); "
              "carried %.3g N\n", 1e3 * free.bottom_z, 1e3 * over.bottom_z, s.stop_reason.c_str(), (long long)s.steps,
              (long long)free.out.summary.steps, carried.norm());
  ASSERT_TRUE(s.converged) << s.stop_reason << " residual " << s.final_residual;
  // Where it hangs without the obstacle, to 1% of the 1 µm gap; the obstacle carries nothing of
  // note (against one element's weight, 7.8e-5 N).
  EXPECT_NEAR(over.bottom_z, free.bottom_z, 1e-2 * kGap);
  EXPECT_LT(carried.norm(), 1e-3 * 1000 * h * h * h * g) << carried.transpose();
}

INSTANTIATE_TEST_SUITE_P(Obstacles, ContactBand,
                         ::testing::Combine(::testing::Values(Obstacle::Torus, Obstacle::Sphere),
                                            ::testing::Values(Integrator::Heun, Integrator::Relaxation)),
                         [](const auto& info) {
                           return std::string(std::get<0>(info.param) == Obstacle::Torus ? "torus_" : "sphere_") +
                                  (std::get<1>(info.param) == Integrator::Heun ? "heun" : "relaxation");
                         });

}  // namespace
}  // namespace vb
