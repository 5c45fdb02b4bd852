// The pneumatic torus device on the OpenCL kernels (PoCL in CI): contact forces balance the loads
// they carry, an inflating torus squeezes tissue up off its base without letting any element in,
// and Coulomb friction holds a block on an incline it would slide down without it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "engine/device/torus.hpp"
#include "engine/error.hpp"
#include "engine/sim/run.hpp"
#include "engine/study/positioning_metrics.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

constexpr double g = 9.81;

TorusSpec torus(const Vec3& centre, const Vec3& axis, double major, std::vector<std::pair<double, double>> minor) {
  TorusSpec t;
  t.name = "ring";
  t.center_m = centre;
  t.axis = axis.normalized();
  for (const auto& [time, r] : minor) t.schedule.push_back({time, r, major});
  return t;
}

double total_mass(const test::Model& m) {
  double mass = 0;
  for (const double x : m.elements.mass_kg) mass += x;
  return mass;
}

Vec3 centroid(const test::Model& m, const std::vector<double>& x) {
  Vec3 c = Vec3::Zero();
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e) c += m.elements.mass_kg[e] * Vec3(x[3 * e], x[3 * e + 1], x[3 * e + 2]);
  return c / total_mass(m);
}

/// A 16 × 16 × 8 mm block (2 mm elements) whose bottom corners rest on the inner slope of a torus
/// (R = 10 mm, r = 5 mm, axis z) under it: the ring cradles it, so it settles centred.
Scene block_in_ring() {
  const double h = 0.002;
  Scene s = test::box_scene(8, 8, 4, h, 30000);
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -g);
  // bottom-corner element centres sit at ρ = 7√2 mm, z = 1 mm: on the tube when its centre is at
  // z = 1 − √(25 − (10 − 9.9)²) mm; start 0.2 mm above that
  const double rho = 0.007 * std::sqrt(2.0), zc = 0.001 - std::sqrt(0.005 * 0.005 - (0.01 - rho) * (0.01 - rho)) - 0.0002;
  s.tori.push_back(torus(Vec3(0.008, 0.008, zc), Vec3::UnitZ(), 0.010, {{0.0, 0.005}}));
  s.solver.precision = Precision::Double;  // the force balance is checked to 1e-4 of the weight
  s.solver.damping_per_s = 60;
  s.solver.dashpot_ratio = 0.1;
  s.stop.equilibrium = 1e-7;
  s.stop.max_steps = 200000;
  return s;
}

TEST(TorusContact, BlockRestingOnTorusPressesWithItsWeight) {
  const Scene s = block_in_ring();
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  const RunOutput out = run_simulation(s, m.lattice, m.elements, sim);
  ASSERT_TRUE(out.summary.converged) << out.summary.stop_reason << " residual " << out.summary.final_residual;
  ASSERT_EQ(out.summary.tori.size(), 1u);
  const TorusResult& t = out.summary.tori[0];
  const Vec3 weight = total_mass(m) * s.gravity.acceleration_m_s2;  // what the tissue puts on its support
  std::printf("ring force %.9g %.9g %.9g N, weight %.9g N, %lld contacts, normal sum %.6g N, peak %.6g Pa, mean %.6g Pa, "
              "penetration %.3g m, steps %lld\n",
              t.force_n.x(), t.force_n.y(), t.force_n.z(), weight.z(), (long long)t.contact_elements, t.normal_force_sum_n,
              t.peak_pressure_pa, t.mean_pressure_pa, t.max_penetration_run_m, (long long)out.summary.steps);
  // Σ residuals bounds the imbalance: n·tol·F_ref = 256 · 1e-7 · E h² ≈ 3e-6 N against W ≈ 0.02 N
  EXPECT_NEAR(t.force_n.z() / weight.z(), 1.0, 1e-3) << "force " << t.force_n.transpose() << " weight " << weight.transpose();
  EXPECT_LT(std::hypot(t.force_n.x(), t.force_n.y()), 1e-3 * weight.norm()) << t.force_n.transpose();
  // It rests on the elements around its bottom edge, each pushing along the tube's normal: the
  // normal forces add up to more than the weight (they lean inwards).
  EXPECT_GE(t.contact_elements, 4);
  EXPECT_GT(t.normal_force_sum_n, weight.norm());
  EXPECT_GT(t.peak_pressure_pa, t.mean_pressure_pa);
  EXPECT_LE(t.max_penetration_run_m, 1e-3 * m.lattice.spacing_m);
  // every element outside the tube at the end (host geometry, independent of the kernels)
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e) {
    const Vec3 x(out.state.position_m[3 * e], out.state.position_m[3 * e + 1], out.state.position_m[3 * e + 2]);
    EXPECT_GE(torus_signed_distance(s.tori[0], sim.time_s(), x), -1e-9) << "element " << e;
  }
}

TEST(TorusContact, TorusAndPlateIndenterShareTheLoad) {
  // The rigid-obstacle table holds indenters and tori together: a plate pressed 0.2 mm onto the
  // cradled block adds its push to the torus's load: F_torus = m·g − F_plate.
  Scene s = block_in_ring();
  IndenterSpec plate;
  plate.kind = IndenterSpec::Kind::Plate;
  plate.start_m = Vec3(0, 0, 0.007 + 0.0002);  // above the top layer (z = 7 mm) by the block's fall
  plate.normal = Vec3(0, 0, -1);
  plate.velocity_m_s = Vec3(0, 0, -0.01);
  plate.travel_time_s = 0.0008 / 0.01;  // 0.8 mm down: the block's settling (≈ 0.3 mm), then a push
  s.indenters.push_back(plate);
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  const RunOutput out = run_simulation(s, m.lattice, m.elements, sim);
  ASSERT_TRUE(out.summary.converged) << out.summary.stop_reason << " residual " << out.summary.final_residual;
  const Vec3 weight = total_mass(m) * s.gravity.acceleration_m_s2;
  const Vec3 plate_force = out.summary.indenters[0].reaction_force_n, ring_force = out.summary.tori[0].force_n;
  EXPECT_GT(plate_force.z(), 0.5 * weight.norm()) << "the plate should press: " << plate_force.transpose();
  const Vec3 expected = weight - plate_force;
  std::printf("plate %.9g N, ring %.9g %.9g %.9g N, expected z %.9g N\n", plate_force.z(), ring_force.x(), ring_force.y(),
              ring_force.z(), expected.z());
  EXPECT_LT((ring_force - expected).norm(), 1e-3 * expected.norm())
      << "ring " << ring_force.transpose() << " expected " << expected.transpose();
}

TEST(TorusContact, TubeThinnerThanTheSpacingIsRefused) {
  Scene s = block_in_ring();
  s.tori[0].schedule = {{0.0, 0.0015, 0.010}};  // r = 1.5 mm < h = 2 mm: could slip between elements
  const auto m = test::make_model(s);
  EXPECT_THROW(Simulator(s, m.lattice, m.elements, test::cl_context()), Error);
}

/// A dome (hemisphere, radius 14 mm, 2 mm elements) on a held base slab (z ≤ 0), gravity towards
/// the base, and optionally a torus around its foot (R = 20 mm, axis z, centre 2 mm below the
/// base) inflating from r = 4 mm (clear of the dome) to r = 9 mm in 0.4 s: its inner edge then
/// reaches 12 mm from the axis at z = 1 mm, inside the dome's 14 mm there, and pushes the foot in
/// and up. The breast, its chest wall and a device ring in miniature.
struct SqueezeRun {
  test::Model model;
  RunOutput out;
  PositioningMetrics metrics;
};

TorusSpec squeeze_ring() { return torus(Vec3(0, 0, -0.002), Vec3::UnitZ(), 0.020, {{0.0, 0.004}, {0.4, 0.009}}); }

SqueezeRun squeeze(bool with_torus) {
  Scene s;
  s.model.spacing_m = 0.002;
  ShapeSpec base, dome;
  base.kind = ShapeSpec::Kind::Box;
  base.min_m = Vec3(-0.016, -0.016, -0.002);
  base.max_m = Vec3(0.016, 0.016, 0);
  dome.kind = ShapeSpec::Kind::Hemisphere;
  dome.radius_m = 0.014;
  dome.axis = Vec3::UnitZ();
  base.label = dome.label = "soft";
  s.model.shapes = {base, dome};
  s.materials["soft"] = test::material("soft", 3000);
  s.anchors.push_back(test::halfspace_anchor("base", Vec3::Zero(), Vec3(0, 0, -1)));
  s.positioning.chest_wall = "base";
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -g);
  if (with_torus) s.tori.push_back(squeeze_ring());
  s.solver.damping_per_s = 30;
  s.solver.dashpot_ratio = 0.1;
  s.stop.equilibrium = 1e-5;
  s.stop.max_steps = 60000;
  SqueezeRun r;
  r.model = test::make_model(s);
  Simulator sim(s, r.model.lattice, r.model.elements, test::cl_context());
  r.out = run_simulation(s, r.model.lattice, r.model.elements, sim);
  r.metrics = compute_positioning_metrics(s, r.model.lattice, r.model.elements, r.out.summary, r.out.state);
  return r;
}

TEST(TorusContact, InflatingTorusLiftsTissueOffTheBaseWithoutPenetration) {
  const SqueezeRun free = squeeze(false), squeezed = squeeze(true);
  ASSERT_TRUE(free.out.summary.converged) << free.out.summary.stop_reason;
  ASSERT_TRUE(squeezed.out.summary.converged) << squeezed.out.summary.stop_reason;
  ASSERT_TRUE(free.metrics.chest_wall && squeezed.metrics.chest_wall);
  const ChestWallMetrics &a = *free.metrics.chest_wall, &b = *squeezed.metrics.chest_wall;
  // Under its weight alone the dome sags towards the base; the squeeze pushes tissue up (measured
  // on PoCL: mean height +0.14 mm, top +0.25 mm; the lattice's ν = 1/4 lets part of the squeeze
  // go into volume loss, a ν = 0.45 neo-Hookean dome lifts +0.33 / +0.43 mm but runs 20× longer).
  EXPECT_LT(a.mean_final_m, a.mean_rest_m);
  EXPECT_GT(b.mean_final_m - a.mean_final_m, 7e-5) << "mean height with " << b.mean_final_m << " without " << a.mean_final_m;
  EXPECT_GT(b.max_final_m - a.max_final_m, 1.2e-4) << "top with " << b.max_final_m << " without " << a.max_final_m;
  const TorusResult& t = squeezed.out.summary.tori[0];
  std::printf("mean height %.4f → %.4f mm, top %.4f → %.4f mm (rest %.4f, %.4f); %lld contacts, squeeze %.4g N, net "
              "%.3g %.3g %.3g N, peak %.4g Pa, penetration %.3g m; steps %lld / %lld\n",
              1e3 * a.mean_final_m, 1e3 * b.mean_final_m, 1e3 * a.max_final_m, 1e3 * b.max_final_m, 1e3 * a.mean_rest_m,
              1e3 * a.max_rest_m, (long long)t.contact_elements, t.normal_force_sum_n, t.force_n.x(), t.force_n.y(),
              t.force_n.z(), t.peak_pressure_pa, t.max_penetration_run_m, (long long)free.out.summary.steps,
              (long long)squeezed.out.summary.steps);
  EXPECT_NEAR(t.minor_radius_m, 0.009, 1e-12);
  EXPECT_GT(t.contact_elements, 20);
  EXPECT_GT(t.normal_force_sum_n, 0.0);
  // A uniform squeeze: the pushes around the ring cancel sideways.
  EXPECT_LT(std::hypot(t.force_n.x(), t.force_n.y()), 0.02 * t.normal_force_sum_n) << t.force_n.transpose();
  // Stated tolerance: no free element deeper than 0.001·h inside the tube at any check.
  const double h = free.model.lattice.spacing_m;
  EXPECT_LE(t.max_penetration_run_m, 1e-3 * h);
  // The host geometry agrees at the end (free elements: held ones are the rigid base).
  const TorusSpec ring = squeeze_ring();
  double deepest = 0;
  for (std::size_t e = 0; e < squeezed.model.lattice.element_count(); ++e) {
    if (squeezed.model.elements.inverse_mass[e] == 0) continue;
    const auto& x = squeezed.out.state.position_m;
    deepest = std::min(deepest, torus_signed_distance(ring, 1.0, Vec3(x[3 * e], x[3 * e + 1], x[3 * e + 2])));
  }
  EXPECT_GE(deepest, -1e-3 * h);
}

/// A 12 × 12 × 6 mm block on the top of a large torus (R = 1 m, r = 0.5 m: nearly flat there),
/// gravity tilted by θ = 15° along the ring, for 0.15 s. The tube's top (z = 0.499 m) runs
/// through the bottom layer's element centres.
struct InclineRun {
  double slide_m = 0;    ///< centroid travel along the incline
  Vec3 ring_force_n = Vec3::Zero();
};

InclineRun incline(double friction, double time_s = 0.15) {
  const double h = 0.002, theta = 15 * std::numbers::pi / 180;
  Scene s = test::box_scene(6, 6, 3, h, 30000);
  s.model.shapes[0].min_m = Vec3(0.994, -0.006, 0.498);  // element centres on the 2 mm grid
  s.model.shapes[0].max_m = Vec3(1.006, 0.006, 0.504);
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = g * Vec3(0, std::sin(theta), -std::cos(theta));
  TorusSpec t = torus(Vec3(0, 0, -0.001), Vec3::UnitZ(), 1.0, {{0.0, 0.5}});
  t.friction = friction;
  s.tori.push_back(t);
  s.solver.precision = Precision::Double;
  s.solver.damping_per_s = 0;  // global damping would brake the sliding itself
  s.solver.dashpot_ratio = 0.3;
  s.stop.equilibrium = 0;
  s.stop.max_time_s = time_s;
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  const RunOutput out = run_simulation(s, m.lattice, m.elements, sim);
  InclineRun r;
  r.slide_m = (centroid(m, out.state.position_m) - centroid(m, element_positions_m(m.lattice))).y();
  r.ring_force_n = out.summary.tori[0].force_n;
  return r;
}

TEST(TorusFriction, HoldsBlockOnInclineBelowTheFrictionAngle) {
  const double theta = 15 * std::numbers::pi / 180;  // tan θ = 0.268
  const InclineRun held = incline(0.4), frictionless = incline(0.0);
  // Frictionless it slides (½·g·sin θ·t² = 29 mm in 0.15 s); with μ = 0.4 > tan θ it only
  // shears elastically (micrometres).
  std::printf("slide μ=0.4: %.3g m, μ=0: %.6g m (free fall along the incline %.6g m); ring force %.6g %.6g %.6g N\n",
              held.slide_m, frictionless.slide_m, 0.5 * g * std::sin(theta) * 0.15 * 0.15, held.ring_force_n.x(),
              held.ring_force_n.y(), held.ring_force_n.z());
  EXPECT_NEAR(frictionless.slide_m, 0.5 * g * std::sin(theta) * 0.15 * 0.15, 0.05 * 0.029);
  EXPECT_LT(std::abs(held.slide_m), 5e-5) << "slid " << held.slide_m << " m";
  // The ring carries the whole weight, tangential part included: the force ratio is tan θ < μ.
  const Vec3 f = held.ring_force_n;
  EXPECT_NEAR(f.y() / -f.z(), std::tan(theta), 0.02) << f.transpose();
}

TEST(TorusFriction, SlidesWithCoulombDragAboveTheFrictionAngle) {
  // μ = 0.2 < tan 15°: it slides with a = g·(sin θ − μ·cos θ) = 0.645 m/s².
  const double theta = 15 * std::numbers::pi / 180, mu = 0.2, t = 0.15;
  const InclineRun r = incline(mu, t);
  const double expected = 0.5 * g * (std::sin(theta) - mu * std::cos(theta)) * t * t;
  std::printf("slide μ=0.2: %.6g m, Coulomb %.6g m\n", r.slide_m, expected);
  EXPECT_NEAR(r.slide_m / expected, 1.0, 0.1) << "slid " << r.slide_m << " m, expected " << expected << " m";
}

}  // namespace
}  // namespace vb
