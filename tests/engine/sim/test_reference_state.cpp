// The unloaded reference state (docs/PHYSICS.md §13): rest offsets must be what the
// kernels treat as rest, and the estimate must find rest offsets from which the CT's gravity
// lands the model on the CT.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

#include "engine/error.hpp"
#include "engine/loads/anchors.hpp"
#include "engine/sim/reference_state.hpp"
#include "engine/sim/run.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

using test::cl_context;

double largest_norm(const std::vector<double>& x) {
  double worst = 0;
  for (std::size_t e = 0; e < x.size() / 3; ++e) worst = std::max(worst, std::hypot(x[3 * e], x[3 * e + 1], x[3 * e + 2]));
  return worst;
}

MaterialSpec law_material(const std::string& law, double E_pa) {
  if (law == "linear") return test::material("soft", E_pa);
  if (law == "biphasic") {
    MaterialSpec m = test::material("soft", E_pa);
    m.law = "biphasic";
    m.cubic = 20;
    m.critical_strain = 0.15;
    return m;
  }
  MaterialSpec m = test::validation_material(law, 0.45);
  const double scale = E_pa / m.youngs_modulus_pa;
  m.youngs_modulus_pa *= scale;
  for (double& mu : m.ogden_mu_pa) mu *= scale;
  return m;
}

std::string law_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string name = info.param;
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
}

// A rest state that is an affine map of the lattice (stretch and rotation) must be force-free
// when the elements sit in it, and loaded when they sit on the lattice: springs take the rest
// lengths, hyperelastic elements the rest shape, the hourglass control the rest connections.
class RestOffsets : public ::testing::TestWithParam<std::string> {};

TEST_P(RestOffsets, AnAffineRestStateIsForceFree) {
  Scene s = test::box_scene(5, 4, 4, 0.004, 3000);
  s.materials["soft"] = law_material(GetParam(), 3000);
  s.solver.precision = Precision::Double;
  s.solver.integrator = Integrator::SymplecticEuler;  // undamped: only the forces matter here
  s.reference_state.active = true;
  const test::Model m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, cl_context());
  const Eigen::Matrix3d A = rotation_from_rpy_deg(Vec3(20, -10, 35)) * Vec3(1.08, 0.95, 1.03).asDiagonal();
  const std::size_t n = m.lattice.element_count();
  std::vector<double> u0(3 * n), zero(3 * n, 0.0);
  for (std::size_t e = 0; e < n; ++e) {
    const Vec3 X = m.lattice.rest_position(e), d = A * X - X;
    for (int c = 0; c < 3; ++c) u0[3 * e + c] = d[c];
  }
  sim.set_rest_offsets(u0);
  sim.upload(zero, zero);
  const double on_lattice = largest_norm(sim.lattice_forces());
  sim.upload(u0, zero);
  const double at_rest = largest_norm(sim.lattice_forces());
  std::cout << GetParam() << ": largest force on the lattice " << on_lattice << " N, in the rest state " << at_rest
            << " N\n";
  EXPECT_GT(on_lattice, 1e-4);  // the stretch is felt: ~E·h²·ε
  EXPECT_LT(at_rest, 1e-10 * on_lattice);
}

INSTANTIATE_TEST_SUITE_P(Laws, RestOffsets, ::testing::Values("linear", "biphasic", "neo-hookean", "ogden"), law_name);

/// A 5×5×8 column (E = 30 kPa) standing on a held base, leaning and sagging under gravity along
/// x and −z in the CT (at the top with the CT as rest: 1.8 mm with springs, 1.7 mm neo-Hookean,
/// 0.64 mm Ogden; the hyperelastic columns' hull masses weigh (4/5)²·6.5/7 of the voxels').
Scene ct_column(const std::string& law) {
  const double h = 0.004;
  Scene s = test::box_scene(5, 5, 8, h, 30000);
  s.materials["soft"] = law_material(law, 30000);
  s.anchors.push_back(test::halfspace_anchor("base", Vec3(0, 0, h), Vec3(0, 0, -1)));
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(9.81, 0, -9.81);
  s.solver.integrator = Integrator::Relaxation;
  s.solver.dt_safety = 0.9;
  s.solver.precision = Precision::Double;
  s.solver.check_every = 10;
  s.stop.equilibrium = 1e-7;
  s.stop.max_steps = 400000;
  s.reference_state.active = true;
  s.reference_state.ct_gravity_m_s2 = s.gravity.acceleration_m_s2;
  s.reference_state.tolerance_m = 1e-6;
  return s;
}

class ReferenceStateColumn : public ::testing::TestWithParam<std::string> {};

TEST_P(ReferenceStateColumn, LoadedByTheCtsGravityItLandsOnTheCt) {
  const Scene s = ct_column(GetParam());
  const test::Model m = test::make_model(s);
  const ReferenceState ref = estimate_reference_state(s, m.lattice, cl_context());
  std::cout << GetParam() << ": " << ref.history.size() << " iterations, residual " << ref.residual_max_m * 1e3
            << " mm, unloaded state up to " << ref.max_rest_offset_m * 1e3 << " mm from the CT\n";
  EXPECT_TRUE(ref.converged);
  EXPECT_LE(ref.residual_max_m, s.reference_state.tolerance_m);
  EXPECT_LE(ref.history.size(), 6u);  // Sellier's iteration contracts fast at these strains
  EXPECT_EQ(ref.unsupported_elements, 0u);

  // Independently: damped Heun from the CT, resting on the estimate, stays on the CT.
  Scene heun = s;
  heun.solver.integrator = Integrator::Heun;
  heun.solver.dt_safety = 0.5;
  heun.solver.damping_per_s = 50;
  heun.solver.dashpot_ratio = 0.1;
  Simulator sim(heun, m.lattice, m.elements, cl_context());
  sim.set_rest_offsets(ref.rest_offset_m);
  const RunOutput run = run_simulation(heun, m.lattice, m.elements, sim);
  EXPECT_TRUE(run.summary.converged);
  EXPECT_LT(largest_norm(run.state.displacement_m), 2 * s.reference_state.tolerance_m);

  // The unloaded column is the CT with the sag undone: about minus the sag the CT would show as
  // rest (the same to first order in the strain, ~1 %; the sag here is 0.6–1.8 mm on 32 mm).
  Scene ct_as_rest = s;
  ct_as_rest.reference_state = ReferenceStateSpec{};
  Simulator plain(ct_as_rest, m.lattice, m.elements, cl_context());
  const RunOutput sag = run_simulation(ct_as_rest, m.lattice, m.elements, plain);
  std::vector<double> mirror(ref.rest_offset_m);
  for (std::size_t i = 0; i < mirror.size(); ++i) mirror[i] += sag.state.displacement_m[i];
  const double sag_m = largest_norm(sag.state.displacement_m);
  std::cout << "  sag with the CT as rest " << sag_m * 1e3 << " mm; |u0 + sag| up to " << largest_norm(mirror) * 1e3
            << " mm\n";
  EXPECT_GT(sag_m, 0.5e-3);  // a load the comparisons below can resolve (0.15 × sag ≫ tolerance)
  EXPECT_NEAR(ref.max_rest_offset_m, sag_m, 0.15 * sag_m);
  EXPECT_LT(largest_norm(mirror), 0.15 * sag_m);
}

INSTANTIATE_TEST_SUITE_P(Laws, ReferenceStateColumn, ::testing::Values("linear", "neo-hookean", "ogden"), law_name);

// Small loads (linear regime): a posture change from the unloaded state moves the model as the
// difference of the two gravities does from the CT taken as rest, Δu = K⁻¹·m·(g₂ − g₁).
TEST(ReferenceState, PostureChangeIsTheGravityDifferenceInTheLinearRegime) {
  Scene s = ct_column("linear");
  s.reference_state.ct_gravity_m_s2 = Vec3(0, 0, -0.5);  // 0.05 g: strains ~1e-3
  s.gravity.acceleration_m_s2 = Vec3(0.5, 0.3, 0);
  s.reference_state.tolerance_m = 1e-8;
  const test::Model m = test::make_model(s);
  const ReferenceState ref = estimate_reference_state(s, m.lattice, cl_context());
  ASSERT_TRUE(ref.converged);
  Simulator sim(s, m.lattice, m.elements, cl_context());
  sim.set_rest_offsets(ref.rest_offset_m);
  const RunOutput turned = run_simulation(s, m.lattice, m.elements, sim);

  Scene difference = s;
  difference.reference_state = ReferenceStateSpec{};
  difference.gravity.acceleration_m_s2 = s.gravity.acceleration_m_s2 - s.reference_state.ct_gravity_m_s2;
  Simulator plain(difference, m.lattice, m.elements, cl_context());
  const RunOutput expected = run_simulation(difference, m.lattice, m.elements, plain);
  std::vector<double> error(turned.state.displacement_m);
  for (std::size_t i = 0; i < error.size(); ++i) error[i] -= expected.state.displacement_m[i];
  const double moved = largest_norm(expected.state.displacement_m);
  std::cout << "posture change " << moved * 1e3 << " mm, differs by " << largest_norm(error) * 1e3 << " mm\n";
  EXPECT_GT(moved, 1e-4);
  EXPECT_LT(largest_norm(error), 0.01 * moved);
}

TEST(ReferenceState, SetRestOffsetsNeedsTheSection) {
  Scene s = test::box_scene(3, 3, 3, 0.004);
  s.solver.integrator = Integrator::SymplecticEuler;
  const test::Model m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, cl_context());
  EXPECT_THROW(sim.set_rest_offsets(std::vector<double>(3 * m.lattice.element_count(), 0.0)), Error);
}

}  // namespace
}  // namespace vb
