// The haptic probe (engine/haptic, docs/HAPTICS.md): its force at a held position must converge
// to the quasi-static force of an ordinary run of the same press, its linearisation must predict
// the force of a small further move, and a blow-up must be detected and reported, not rendered;
// a press that folds the lattice must be reported as folded (and the run go on), a valid one not.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "engine/error.hpp"
#include "engine/haptic/haptic_bench.hpp"
#include "engine/haptic/haptic_loop.hpp"
#include "engine/haptic/haptic_probe.hpp"
#include "engine/sim/run.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

constexpr double kH = 0.002, kRadius = 0.004, kDepth = 0.002;

/// A 10×10×6 block (E = 3 kPa) on a held base layer, a 4 mm sphere just touching the middle of
/// its top face, relaxed (the haptic probe's quasi-static update).
Scene press_scene() {
  Scene s = test::box_scene(10, 10, 7, kH);
  s.model.shapes[0].min_m.z() = -kH;
  s.model.shapes[0].max_m.z() = 6 * kH;
  s.anchors.push_back(test::halfspace_anchor("base", Vec3::Zero(), Vec3(0, 0, -1)));
  IndenterSpec ball;
  ball.kind = IndenterSpec::Kind::Sphere;
  ball.radius_m = kRadius;
  ball.start_m = Vec3(0.01, 0.01, 5.5 * kH + kRadius);  // touching the top layer's centres
  s.indenters.push_back(ball);
  s.solver.integrator = Integrator::Relaxation;
  s.solver.dt_safety = 0.9;
  s.solver.precision = Precision::Double;
  s.solver.check_every = 20;
  s.stop.equilibrium = 1e-7;
  s.stop.max_steps = 400000;
  return s;
}

/// The same press as an ordinary run: the ball moves down kDepth and the run stops at equilibrium.
Vec3 quasi_static_force(const Scene& base, const test::Model& m, double depth) {
  Scene s = base;
  s.indenters[0].velocity_m_s = Vec3(0, 0, -0.01);
  s.indenters[0].travel_time_s = depth / 0.01;
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  const RunOutput out = run_simulation(s, m.lattice, m.elements, sim);
  EXPECT_TRUE(out.summary.converged) << out.summary.stop_reason;
  return out.summary.indenters[0].reaction_force_n;
}

/// Synchronous updates until the residual is below tol (or `max` updates).
void settle(HapticProbe& probe, double tol, int max = 20000) {
  for (int i = 0; i < max; ++i) {
    ASSERT_TRUE(probe.update()) << probe.last_update().message;
    if (probe.last_update().residual < tol && i > 10) return;
  }
  FAIL() << "no equilibrium after " << max << " updates; residual " << probe.last_update().residual;
}

TEST(HapticProbe, HeldProbeForceConvergesToTheQuasiStaticPress) {
  const Scene s = press_scene();
  const test::Model m = test::make_model(s);
  const Vec3 reference = quasi_static_force(s, m, kDepth);
  ASSERT_GT(reference.z(), 1e-3) << "the tissue pushes the ball up";

  // The haptic loop in real time: down in 0.2 s, then held for 1.3 s (hundreds of updates even
  // on 2 loaded CPU cores). Its last output is the press's force.
  {
    HapticProbe probe(s, m.lattice, m.elements, test::cl_context());
    const Vec3 start = s.indenters[0].start_m, held = start - Vec3(0, 0, kDepth);
    ProbeTrajectory press;
    press.time_s = {0, 0.2};
    press.position_m = {start, held};
    HapticLoopOptions loop;
    loop.rate_hz = 1000;
    loop.seconds = 1.5;
    const HapticLoopResult r = run_haptic_loop(probe, press, loop);
    ASSERT_FALSE(r.blown_up) << r.message;
    ASSERT_GT(r.samples.size(), 100u);
    const Vec3 loop_force = r.samples.back().force_n;
    std::cout << "quasi-static press " << reference.transpose() << " N; haptic loop after 1.5 s (" << r.updates
              << " updates, " << r.samples.size() << " outputs) " << loop_force.transpose() << " N\n";
    EXPECT_NEAR(loop_force.z(), reference.z(), 0.02 * reference.z());
  }
  // Without the clock (the same updates on any machine): the probe sent straight to the held
  // position and updated until the reference run's residual.
  HapticProbe probe(s, m.lattice, m.elements, test::cl_context());
  probe.set_probe_position(s.indenters[0].start_m - Vec3(0, 0, kDepth));
  settle(probe, s.stop.equilibrium);
  const Vec3 settled = probe.force();
  std::cout << "settled haptic force " << settled.transpose() << " N after " << probe.last_update().count
            << " updates\n";
  // Both stop at a residual of 1e-7·E·h² per element (a force error far below 1e-6 N). What
  // remains is contact: an element within the contact band (1e-3·h of the surface,
  // kernels/common.cl) may or may not be carried, depending on the path, which makes the
  // frictionless equilibrium unique only to about the band times the contact stiffness, ~1e-5 N
  // here (runs along different paths differ by 3e-4 to 1.1e-3 of the force).
  EXPECT_NEAR(settled.z(), reference.z(), 2e-3 * reference.z());
  EXPECT_LT((settled - reference).norm(), 2e-3 * reference.norm());
}

TEST(HapticProbe, LinearisationPredictsTheForceOfASmallFurtherPress) {
  const Scene s = press_scene();
  const test::Model m = test::make_model(s);
  HapticProbe probe(s, m.lattice, m.elements, test::cl_context());
  const Vec3 start = s.indenters[0].start_m;
  // Press in small moves, each settled, so K is the secant of equilibrium forces.
  const int moves = 8;
  for (int i = 1; i <= moves; ++i) {
    probe.set_probe_position(start - Vec3(0, 0, kDepth * i / moves));
    settle(probe, 1e-6);
  }
  const HapticUpdate at = probe.last_update();
  EXPECT_LT(at.stiffness_n_m(2, 2), 0.0) << "deeper is harder: ∂Fz/∂z < 0";
  const Vec3 deeper = at.probe_m - Vec3(0, 0, 0.1 * kDepth);
  probe.set_probe_position(deeper);
  const Vec3 predicted = probe.force();  // before any update at the new position
  settle(probe, 1e-6);
  const Vec3 actual = probe.force();
  std::cout << "force at depth " << at.force_n.z() << " N; 0.2 mm deeper predicted " << predicted.z()
            << " N, settled " << actual.z() << " N\n";
  ASSERT_GT(actual.z(), at.force_n.z());
  // The secant over the last move predicts the increment within 10% (Hertz: F ∝ δ^1.5, so the
  // secant over the last 0.25 mm undershoots the next 0.2 mm by 6%; measured: 4% under).
  EXPECT_NEAR(predicted.z() - at.force_n.z(), actual.z() - at.force_n.z(), 0.10 * (actual.z() - at.force_n.z()));
}

TEST(HapticProbe, BlowUpIsDetectedAndReported) {
  Scene s = press_scene();
  s.solver.integrator = Integrator::SymplecticEuler;
  s.solver.damping_per_s = 10;
  const test::Model m = test::make_model(s);
  {
    // 20× the stable step: the first press diverges.
    Simulator probe_dt(s, m.lattice, m.elements, test::cl_context());
    s.solver.dt_s = 20 * probe_dt.time_step().stable_limit_s;
  }
  HapticProbe probe(s, m.lattice, m.elements, test::cl_context());
  ProbeTrajectory press;
  press.time_s = {0, 0.1};
  press.position_m = {s.indenters[0].start_m, s.indenters[0].start_m - Vec3(0, 0, kDepth)};
  HapticLoopOptions loop;
  loop.seconds = 5;
  const HapticLoopResult r = run_haptic_loop(probe, press, loop);
  EXPECT_TRUE(r.blown_up);
  EXPECT_NE(r.message.find("blew up"), std::string::npos) << r.message;
  EXPECT_FALSE(probe.update()) << "a blown-up probe does not update again";
  for (const HapticSample& sample : r.samples) EXPECT_TRUE(sample.force_n.allFinite());
}

/// The haptic sample's block (h = 2 mm, E = 3 kPa, held base, a 5 mm ball touching the top
/// layer's centres; data-samples/haptic/block.toml), smaller: 16 × 16 × 15 elements. The probe is
/// sent `depth` down and updated synchronously (the moves take depth / 0.5 mm updates), then held
/// for `hold` updates; a last fold check reads the final state.
HapticUpdate press_block(double depth, int hold) {
  const Scene s = haptic_bench_scene(4096, Precision::Float);
  const test::Model m = test::make_model(s);
  HapticProbe probe(s, m.lattice, m.elements, test::cl_context());
  probe.set_probe_position(s.indenters[0].start_m - Vec3(0, 0, depth));
  const int moves = int(std::ceil(depth / (0.25 * s.model.spacing_m)));
  for (int i = 0; i < moves + hold; ++i) EXPECT_TRUE(probe.update()) << probe.last_update().message;
  probe.check_fold();
  const HapticUpdate u = probe.last_update();
  std::cout << depth * 1e3 << " mm press, " << m.lattice.element_count() << " elements: " << u.count
            << " updates, force " << u.force_n.z() << " N, residual " << u.residual << "; " << u.fold_checks
            << " fold checks, " << u.folded_checks << " folded (first at update " << u.first_fold_update
            << "), lowest det F " << u.lowest_det_f << ", final " << u.min_det_f << " (" << u.inverted_elements
            << " inverted), checks took " << 1e3 * u.fold_check_wall_s << " ms\n";
  // The probe's moves alone trigger a check every half spacing (two updates of 0.25 h).
  EXPECT_GE(u.fold_checks, moves / 2);
  return u;
}

TEST(HapticProbe, DeepPressIsReportedFolded) {
  // 8 mm with the 5 mm ball folds the layer under it (docs/VALIDATION.md, "the haptic sample in
  // triangle contact": det F −0.54 in vertex contact). A validity warning, not a blow-up.
  const HapticUpdate u = press_block(0.008, 200);
  EXPECT_FALSE(u.blown_up) << u.message;
  EXPECT_TRUE(u.folded());
  EXPECT_LE(u.lowest_det_f, 0.0);
  EXPECT_GT(u.first_fold_update, 0);
  EXPECT_LE(u.first_fold_update, u.count);
  EXPECT_GE(u.folded_checks, 1);
}

TEST(HapticProbe, ShallowPressIsNotFolded) {
  // 2 mm: min det F about 0.57 at equilibrium (docs/VALIDATION.md).
  const HapticUpdate u = press_block(0.002, 200);
  EXPECT_FALSE(u.blown_up) << u.message;
  EXPECT_FALSE(u.folded());
  EXPECT_EQ(u.inverted_elements, 0);
  EXPECT_GT(u.lowest_det_f, 0.3);
  EXPECT_LT(u.lowest_det_f, 0.9) << "the press compresses the layer under the ball";
  EXPECT_EQ(u.first_fold_update, -1);
}

TEST(HapticTrajectory, InterpolatesLinearlyAndHoldsAtTheEnds) {
  const ProbeTrajectory t = trajectory_from_rows({{0, 0, 0, 10}, {1, 0, 0, 0}, {3, 2, 0, 0}}, "test");
  EXPECT_TRUE(t.at(-1).isApprox(Vec3(0, 0, 0.01)));
  EXPECT_TRUE(t.at(0.5).isApprox(Vec3(0, 0, 0.005)));
  EXPECT_TRUE(t.at(2).isApprox(Vec3(0.001, 0, 0)));
  EXPECT_TRUE(t.at(10).isApprox(Vec3(0.002, 0, 0)));
  EXPECT_THROW(trajectory_from_rows({{0, 0, 0, 0}, {0, 1, 1, 1}}, "test"), Error);
  EXPECT_THROW(trajectory_from_rows({{-1, 0, 0, 0}}, "test"), Error);
}

TEST(HapticTrajectory, IntervalStatistics) {
  std::vector<double> intervals(99, 0.001);
  intervals.push_back(0.004);
  const IntervalStats s = interval_stats(intervals, 0.001);
  EXPECT_NEAR(s.mean_s, 0.00103, 1e-9);
  EXPECT_DOUBLE_EQ(s.p50_s, 0.001);
  EXPECT_DOUBLE_EQ(s.max_s, 0.004);
  EXPECT_EQ(s.missed, 1);
}

}  // namespace
}  // namespace vb
