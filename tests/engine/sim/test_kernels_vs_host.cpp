// The OpenCL kernels against the double-precision host reference of the same forces.
#include <gtest/gtest.h>

#include <random>

#include "engine/sim/host_reference.hpp"
#include "engine/sim/simulator.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

/// A 6×5×4 block with a stiff spherical inclusion, base held, dashpots on: every code path of the
/// force kernel (boundaries, two materials, dashpot, held neighbours).
Scene two_material_scene(Precision precision, Integrator integrator) {
  Scene s = test::box_scene(6, 5, 4, 0.002);
  ShapeSpec inclusion;
  inclusion.kind = ShapeSpec::Kind::Sphere;
  inclusion.center_m = Vec3(0.006, 0.005, 0.004);
  inclusion.radius_m = 0.0025;
  inclusion.label = "stiff";
  s.model.shapes.push_back(inclusion);
  s.materials["stiff"] = test::material("stiff", 30000, 1100);
  s.anchors.push_back(test::halfspace_anchor("base", Vec3(0, 0, 0.0015), Vec3(0, 0, -1)));
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0.5, -1.0, -9.81);
  s.solver.precision = precision;
  s.solver.integrator = integrator;
  s.solver.dashpot_ratio = 0.2;
  s.solver.damping_per_s = 3.0;
  return s;
}

/// Random state of amplitude ~5% strain; held elements keep their prescribed displacement.
void random_state(const ElementArrays& el, std::vector<double>& u, std::vector<double>& v, double h) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> r(-1, 1);
  u = el.displacement_m;
  v.assign(u.size(), 0.0);
  for (std::size_t i = 0; i < u.size(); ++i) {
    if (el.inverse_mass[i / 3] == 0) continue;
    u[i] += 0.05 * h * r(rng);
    v[i] = 0.01 * r(rng);
  }
}

double max_abs(const std::vector<double>& a) {
  double m = 0;
  for (double x : a) m = std::max(m, std::abs(x));
  return m;
}

double max_abs_diff(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

struct Case {
  Precision precision;
  double force_tolerance;  // relative to the largest force
};

class KernelForces : public ::testing::TestWithParam<Case> {};

TEST_P(KernelForces, MatchHostReference) {
  const Case c = GetParam();
  const Scene s = two_material_scene(c.precision, Integrator::Heun);
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  HostReference host(m.lattice, m.elements, s);
  std::vector<double> u, v;
  random_state(m.elements, u, v, m.lattice.spacing_m);
  sim.upload(u, v);
  const auto f_dev = sim.lattice_forces();
  const auto f_host = host.lattice_forces(u, v);
  const double scale = max_abs(f_host);
  ASSERT_GT(scale, 0);
  EXPECT_LE(max_abs_diff(f_dev, f_host) / scale, c.force_tolerance)
      << "precision " << (c.precision == Precision::Double ? "double" : "float");
}

INSTANTIATE_TEST_SUITE_P(Precisions, KernelForces,
                         ::testing::Values(Case{Precision::Double, 1e-12}, Case{Precision::Float, 1e-5}),
                         [](const auto& info) { return info.param.precision == Precision::Double ? "Double" : "Float"; });

class KernelSteps : public ::testing::TestWithParam<Integrator> {};

TEST_P(KernelSteps, DoublePrecisionTrajectoryMatchesHost) {
  const Scene s = two_material_scene(Precision::Double, GetParam());
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  HostReference host(m.lattice, m.elements, s);
  std::vector<double> u, v;
  random_state(m.elements, u, v, m.lattice.spacing_m);
  sim.upload(u, v);
  host.u = u;
  host.v = v;
  const int steps = 200;
  sim.advance(steps);
  host.step(sim.dt_s(), steps);
  std::vector<double> u_dev, v_dev;
  sim.download(u_dev, v_dev);
  EXPECT_LE(max_abs_diff(u_dev, host.u), 1e-10 * max_abs(host.u));
  EXPECT_LE(max_abs_diff(v_dev, host.v), 1e-9 * max_abs(host.v));
}

TEST_P(KernelSteps, FloatAndDoubleAgree) {
  // Stated tolerance: after settling 2000 steps under gravity, float displacements agree with
  // double to 1e-4 of the largest displacement.
  std::vector<double> u[2], v[2];
  int i = 0;
  for (Precision p : {Precision::Double, Precision::Float}) {
    const Scene s = two_material_scene(p, GetParam());
    const auto m = test::make_model(s);
    Simulator sim(s, m.lattice, m.elements, test::cl_context());
    sim.advance(2000);
    sim.download(u[i], v[i]);
    ++i;
  }
  EXPECT_LE(max_abs_diff(u[0], u[1]), 1e-4 * max_abs(u[0]));
}

INSTANTIATE_TEST_SUITE_P(Integrators, KernelSteps,
                         ::testing::Values(Integrator::Heun, Integrator::SymplecticEuler),
                         [](const auto& info) { return info.param == Integrator::Heun ? "Heun" : "SymplecticEuler"; });

}  // namespace
}  // namespace vb
