// Contact that cannot be outrun (docs/PHYSICS.md, "Indenters"): held plates keep their layer at
// speeds beyond the contact band per step, an indenter too fast for the lattice, one starting
// inside the body and a plate driven into the anchor each get their own message, not a run that
// reports success or blames the time step.
#include <gtest/gtest.h>

#include <cstdio>

#include "engine/error.hpp"
#include "engine/sim/contact_checks.hpp"
#include "engine/sim/run.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

constexpr double kH = 0.002;

/// Runs the scene and returns the error's text (problem and hint), or "" when it ran.
std::string run_error(const Scene& s) {
  const test::Model m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  try {
    run_simulation(s, m.lattice, m.elements, sim);
  } catch (const Error& e) {
    return e.problem() + " | " + e.hint();
  }
  return "";
}

class HeldTension : public ::testing::TestWithParam<Integrator> {};

/// The tension test of docs/SCENE.md: a cube of ten 2 mm layers between two slide plates through
/// its outer layers' centres, the top one pulled up at 0.05 m/s by 30%. The plate moves several
/// contact bands (10⁻³·h) per step; the top layer must follow it and pull on it.
TEST_P(HeldTension, TheManualsTensionTestHoldsTheTopLayer) {
  const int n = 10;
  const double stretch = 1.3, speed = 0.05, travel = (stretch - 1) * (n - 1) * kH;
  Scene s = test::box_scene(4, 4, n, kH);
  s.indenters = test::plate_pair(n, kH, stretch, IndenterSpec::Contact::Slide, speed);
  s.solver.integrator = GetParam();
  s.solver.precision = Precision::Double;
  s.solver.dashpot_ratio = GetParam() == Integrator::Relaxation ? 0 : 0.1;
  s.solver.damping_per_s = GetParam() == Integrator::Relaxation ? 0 : 100;
  s.stop.equilibrium = 1e-6;
  s.stop.max_steps = 200000;
  const test::Model m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  std::printf("dt %.3g s: the plate moves %.3g·h per step\n", sim.dt_s(), speed * sim.dt_s() / kH);
  ASSERT_GT(speed * sim.dt_s(), 2e-3 * kH) << "the plate must move beyond the contact band per step";
  const RunOutput out = run_simulation(s, m.lattice, m.elements, sim);
  ASSERT_TRUE(out.summary.converged) << out.summary.stop_reason;
  double lowest_top = INFINITY;
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e)
    if (m.lattice.voxel_ijk(e)[2] == n - 1) lowest_top = std::min(lowest_top, out.state.displacement_m[3 * e + 2]);
  EXPECT_NEAR(lowest_top, travel, 1e-3 * kH) << "every top-layer element moves with the plate";
  const double pull = out.summary.indenters[1].reaction_force_n.z(), base = out.summary.indenters[0].reaction_force_n.z();
  EXPECT_LT(pull, 0) << "the tissue pulls the top plate back";
  EXPECT_NEAR(pull, -base, 1e-3 * std::abs(pull)) << "the plates carry equal and opposite forces";
  // 30% tension of springs (E = 3 kPa) over the 8 mm × 8 mm section: within a factor of the
  // uniaxial E·A·strain (the lattice's own E and the free sides' contraction aside).
  const double nominal = 3000 * (4 * kH) * (4 * kH) * (stretch - 1);
  EXPECT_GT(-pull, 0.5 * nominal);
  EXPECT_LT(-pull, 1.5 * nominal);
}

INSTANTIATE_TEST_SUITE_P(Integrators, HeldTension, ::testing::Values(Integrator::Heun, Integrator::Relaxation),
                         [](const auto& info) { return info.param == Integrator::Heun ? "Heun" : "Relaxation"; });

Scene anchored_block() {
  Scene s = test::box_scene(6, 6, 5, kH);
  s.anchors.push_back(test::halfspace_anchor("base", Vec3(0, 0, kH), Vec3(0, 0, -1)));
  s.solver.dashpot_ratio = 0.1;
  s.solver.damping_per_s = 50;
  s.stop.equilibrium = 1e-6;
  s.stop.max_steps = 20000;
  return s;
}

IndenterSpec ball(const Vec3& centre, double radius, const Vec3& velocity, double travel_time_s) {
  IndenterSpec b;
  b.kind = IndenterSpec::Kind::Sphere;
  b.radius_m = radius;
  b.start_m = centre;
  b.velocity_m_s = velocity;
  b.travel_time_s = travel_time_s;
  return b;
}

TEST(ContactLimits, IndenterFasterThanTheLatticeIsRefusedWithTheSafeSpeed) {
  Scene s = anchored_block();
  s.indenters.push_back(ball(Vec3(0.006, 0.006, 0.016), 0.004, Vec3(0, 0, -1000), 4e-6));  // 4 mm deep
  const std::string error = run_error(s);
  EXPECT_NE(error.find("indenter 1 (sphere) moves"), std::string::npos) << error;
  EXPECT_NE(error.find("largest safe speed"), std::string::npos) << error;
  // At the safe speed it runs (and the ball is pushed back by the tissue).
  const test::Model m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  const double safe = kMaxObstacleTravelPerStep * kH / sim.dt_s();
  s.indenters[0].velocity_m_s = Vec3(0, 0, -0.99 * safe);
  s.indenters[0].travel_time_s = 0.002 / (0.99 * safe);
  EXPECT_EQ(run_error(s), "");
}

TEST(ContactLimits, TorusInflatingFasterThanTheLatticeIsRefused) {
  Scene s = anchored_block();
  TorusSpec t;
  t.name = "ring";
  t.center_m = Vec3(0.006, 0.006, 0.005);
  t.schedule = {{0.0, 0.003, 0.012}, {1e-5, 0.006, 0.012}};  // the tube swells 3 mm in 10 µs
  s.tori.push_back(t);
  const std::string error = run_error(s);
  EXPECT_NE(error.find("torus 'ring' (its tube surface) moves"), std::string::npos) << error;
}

TEST(ContactLimits, IndenterOrTorusStartingInsideTheBodyIsRefused) {
  Scene inside = anchored_block();
  inside.indenters.push_back(ball(Vec3(0.006, 0.006, 0.008), 0.003, Vec3::Zero(), INFINITY));
  std::string error = run_error(inside);
  EXPECT_NE(error.find("indenter 1 (sphere) starts inside the body"), std::string::npos) << error;

  Scene torus = anchored_block();
  TorusSpec t;
  t.name = "inner";
  t.center_m = Vec3(0.006, 0.006, 0.006);  // a tube of r = 2 mm around a 3 mm circle in the block
  t.schedule = {{0.0, 0.002, 0.003}, {0.05, 0.0025, 0.003}};
  torus.tori.push_back(t);
  error = run_error(torus);
  EXPECT_NE(error.find("torus 'inner' starts inside the body"), std::string::npos) << error;

  // Touching is allowed: a plate through the top layer's centres, a ball resting on it.
  Scene touching = anchored_block();
  IndenterSpec plate;
  plate.kind = IndenterSpec::Kind::Plate;
  plate.start_m = Vec3(0, 0, 4.5 * kH);
  plate.normal = Vec3(0, 0, -1);
  touching.indenters.push_back(plate);
  touching.indenters.push_back(ball(Vec3(0.005, 0.005, 4.5 * kH + 0.003), 0.003, Vec3::Zero(), INFINITY));
  EXPECT_EQ(run_error(touching), "");
}

TEST(ContactLimits, PlateDrivenIntoTheAnchorIsNamedNotTheTimeStep) {
  Scene s = anchored_block();
  IndenterSpec plate;
  plate.kind = IndenterSpec::Kind::Plate;
  plate.start_m = Vec3(0, 0, 4.5 * kH);
  plate.normal = Vec3(0, 0, -1);
  plate.velocity_m_s = Vec3(0, 0, -0.05);
  plate.travel_time_s = 5 * kH / 0.05;  // to 1 mm below the held base layer's centres
  s.indenters.push_back(plate);
  s.stop.max_steps = 200000;
  const std::string error = run_error(s);
  EXPECT_NE(error.find("indenter 1 (plate) has been driven"), std::string::npos) << error;
  EXPECT_NE(error.find("held element"), std::string::npos) << error;
  EXPECT_EQ(error.find("smaller solver.dt"), std::string::npos) << error;
}

}  // namespace
}  // namespace vb
