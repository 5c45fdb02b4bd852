// The CPU stepping kernels on float8 vectors, 8 free elements per work-item
// (kernels/integrate_lanes.cl, VB_LANES), against the real4 kernels they replace on CPUs
// (kernels/integrate.cl, PlanOverrides::lanes = false). Run where the default device is a CPU (PoCL in CI);
// on a GPU the lanes form is not used and the comparisons skip.
#include <gtest/gtest.h>

#include <cstdlib>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "engine/sim/simulator.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"
#include "tests/engine/sim/trajectory_compare.hpp"

namespace vb {
namespace {

/// A 9×10×11 block, base layer held (900 free elements, the lanes kernels' work-items: not a
/// multiple of the vector width, so the last vector is part-filled), under gravity, with dashpots
/// and global damping: every term of the lanes kernels. Its rows of 9 give both of their ways to
/// read neighbours: a work-item inside a row reads most directions as runs of 8 (vector loads);
/// a work-item across two rows, and any direction off the block, reads lane by lane.
Scene block(bool volume, Integrator integrator = Integrator::Heun) {
  Scene s = test::box_scene(9, 10, 11, 0.005, 3000);
  s.anchors.push_back(test::halfspace_anchor("base", Vec3(0, 0, 0.0025), Vec3(0, 0, -1)));
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -9.81);
  s.solver.precision = Precision::Float;
  s.solver.integrator = integrator;
  s.solver.dashpot_ratio = 0.1;
  s.solver.damping_per_s = 5;
  s.volume.preserve = volume;
  return s;
}

std::unique_ptr<Simulator> make_simulator(const Scene& s, const test::Model& m, bool lanes) {
  PlanOverrides o;
  o.lanes = lanes;
  return std::make_unique<Simulator>(s, m.lattice, m.elements, test::cl_context(), o);
}

/// u then v after 300 steps from rest, checks every 100 (relaxation sets its damping there),
/// gravity turned after step 100 (a posture change), a new state uploaded after step 200, with
/// the lanes kernels or the real4 ones; empty when the device does not use the lanes form.
std::vector<double> run(const Scene& s, bool lanes) {
  const test::Model m = test::make_model(s);
  const std::unique_ptr<Simulator> made = make_simulator(s, m, lanes);
  Simulator& sim = *made;
  if (sim.lanes() != lanes) return {};
  for (int k = 0; k < 3; ++k) {
    sim.advance(100);
    EXPECT_EQ(sim.check().nonfinite_elements, 0);
    if (k == 0) sim.set_gravity(Vec3(0, 4.9, -8.5));
    if (k == 1) {  // a new state, held elements displaced too: the lanes kernels never write those
      std::vector<double> u, v;
      sim.download(u, v);
      for (std::size_t i = 0; i < u.size(); ++i) u[i] += 1e-4 * double(i % 7);
      sim.upload(u, v);
    }
  }
  std::vector<double> u, v;
  sim.download(u, v);
  u.insert(u.end(), v.begin(), v.end());
  return u;
}

// The same Heun, symplectic Euler and dynamic relaxation steps as the real4 kernels, term by
// term: a wrong sign, a missing term (gravity, damping, a dashpot, a connection direction), a
// held element that moved, a free element left out, or a held element's stale entry in the
// scratch state (the lanes kernels step the free elements only) would give another trajectory.
// The forms differ only where the compiler may fuse a·b + c differently (-cl-mad-enable) in
// float8 and float4 code; on PoCL (AMD EPYC Zen 3, AVX2; an earlier scalar form on Zen 4,
// AVX-512) they agreed exactly; the bound leaves room for other fusing.
TEST(LanesStep, MatchesReal4Kernels) {
  const std::map<Integrator, std::string> names = {
      {Integrator::Heun, "Heun"}, {Integrator::SymplecticEuler, "symplectic Euler"}, {Integrator::Relaxation, "relaxation"}};
  for (const auto& [integrator, integrator_name] : names)
    for (const bool volume : {false, true}) {
      const std::string name = integrator_name + (volume ? " with" : " without") + " the volume constraint";
      const std::vector<double> lanes = run(block(volume, integrator), true);
      if (lanes.empty()) GTEST_SKIP() << "the lanes kernels are used on CPU devices only";
      const double d = test::relative_difference(lanes, run(block(volume, integrator), false));
      std::cout << name << ": lanes vs real4 kernels, largest difference over largest |u|, |v|: " << d << "\n";
      EXPECT_LE(d, 1e-5) << name;
    }
}

// The lanes form replaces only what it computes: float steps of spring models with no contact,
// device, rest offsets or folded projections. Anything else keeps the real4 kernels.
TEST(LanesStep, UsedOnlyForPlainFloatSpringModels) {
  const Scene plain = block(false);
  const test::Model m = test::make_model(plain);
  if (!make_simulator(plain, m, true)->lanes()) GTEST_SKIP() << "the lanes kernels are used on CPU devices only";
  EXPECT_FALSE(make_simulator(plain, m, false)->lanes()) << "lanes = false";

  Scene dbl = plain;
  dbl.solver.precision = Precision::Double;
  EXPECT_FALSE(make_simulator(dbl, test::make_model(dbl), true)->lanes()) << "double";

  Scene ogden = plain;
  ogden.materials["soft"] = test::validation_material("ogden", 0.45);
  EXPECT_FALSE(make_simulator(ogden, test::make_model(ogden), true)->lanes()) << "hyperelastic";

  Scene biphasic = plain;
  biphasic.materials["soft"].law = "biphasic";
  biphasic.materials["soft"].cubic = 20;
  biphasic.materials["soft"].critical_strain = 0.1;
  EXPECT_FALSE(make_simulator(biphasic, test::make_model(biphasic), true)->lanes()) << "biphasic";

  Scene pressed = plain;
  IndenterSpec sphere;
  sphere.radius_m = 0.01;
  sphere.start_m = Vec3(0.0225, 0.025, 0.08);
  pressed.indenters.push_back(sphere);
  EXPECT_FALSE(make_simulator(pressed, test::make_model(pressed), true)->lanes()) << "indenter";
}

}  // namespace
}  // namespace vb
