// A frictionless flat plate pressed 0.5% into the top of a block with a held base: the reaction
// force must match the block's stiffness, measured independently by the lattice's static response
// to the same plate displacement: K = E_block·A/L, E_block from the stretch measurement.
#include <gtest/gtest.h>

#include "engine/sim/run.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

TEST(Indenter, PlateReactionMatchesBlockStiffness) {
  const double h = 0.002, E = 3000;
  const int nxy = 12, nz = 7;  // plus a held base layer
  Scene s = test::box_scene(nxy, nxy, nz + 1, h, E);
  s.model.shapes[0].min_m.z() = -h;
  s.model.shapes[0].max_m.z() = nz * h;
  s.anchors.push_back(test::halfspace_anchor("base", Vec3::Zero(), Vec3(0, 0, -1)));
  const double top = (nz - 0.5) * h;         // centre of the top layer
  const double depth = 0.005 * (top + 0.5 * h);  // 0.5% of the column length
  IndenterSpec plate;
  plate.kind = IndenterSpec::Kind::Plate;
  plate.start_m = Vec3(0, 0, top);
  plate.normal = Vec3(0, 0, -1);
  plate.velocity_m_s = Vec3(0, 0, -0.01);
  plate.travel_time_s = depth / 0.01;
  s.indenters.push_back(plate);
  s.solver.damping_per_s = 250;  // about critical for the first axial mode
  s.solver.dashpot_ratio = 0.1;
  s.solver.precision = Precision::Double;  // a 1e-7 residual is below float round-off
  s.stop.equilibrium = 1e-7;
  s.stop.max_steps = 200000;
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  const RunOutput out = run_simulation(s, m.lattice, m.elements, sim);
  ASSERT_TRUE(out.summary.converged) << out.summary.stop_reason;
  ASSERT_EQ(out.summary.indenters.size(), 1u);
  const Vec3 force = out.summary.indenters[0].reaction_force_n;
  EXPECT_EQ(out.summary.indenters[0].contact_elements, nxy * nxy);

  // Closed form for a block compressed between a frictionless plate and a held base, uniaxial
  // stress over the voxel area (12 voxels across: surface columns make E_block ≈ 0.96·E).
  const double L = top + 0.5 * h;  // from the held layer's centre to the plate
  const double expected = E * (nxy * h) * (nxy * h) * depth / L;
  // the tissue pushes the plate back (+z)
  EXPECT_NEAR(force.z() / expected, 1.0, 0.10) << "force " << force.transpose() << " expected " << expected;
  EXPECT_LT(std::hypot(force.x(), force.y()), 1e-3 * std::abs(force.z()));
}

TEST(Indenter, SphereIndenterPushesElementsOutOfItsVolume) {
  const double h = 0.002;
  Scene s = test::box_scene(10, 10, 6, h);
  s.anchors.push_back(test::halfspace_anchor("base", Vec3(0, 0, h), Vec3(0, 0, -1)));
  IndenterSpec ball;
  ball.kind = IndenterSpec::Kind::Sphere;
  ball.radius_m = 0.004;
  ball.start_m = Vec3(0.01, 0.01, 6 * h + 0.004);
  ball.velocity_m_s = Vec3(0, 0, -0.02);
  ball.travel_time_s = 0.002 / 0.02;  // 2 mm deep
  s.indenters.push_back(ball);
  s.solver.damping_per_s = 50;
  s.solver.dashpot_ratio = 0.1;
  s.stop.max_steps = 4000;
  s.stop.equilibrium = 0;
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  const RunOutput out = run_simulation(s, m.lattice, m.elements, sim);
  const Vec3 centre = sim.indenter_position(0, sim.time_s());
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e) {
    const Vec3 x(out.state.position_m[3 * e], out.state.position_m[3 * e + 1], out.state.position_m[3 * e + 2]);
    EXPECT_GE((x - centre).norm(), ball.radius_m * (1 - 1e-5)) << "element " << e << " inside the indenter";
  }
  EXPECT_GT(out.summary.indenters[0].contact_elements, 0);
  EXPECT_GT(out.summary.indenters[0].reaction_force_n.z(), 0.0) << "tissue pushes the ball up";
}

}  // namespace
}  // namespace vb
