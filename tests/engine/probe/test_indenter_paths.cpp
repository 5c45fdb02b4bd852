// Indenter shapes and paths: a recorded trajectory drives the indenter through its knots; a
// capsule (finger) pushes the elements out of its volume; gravity settles before the presses;
// the [probe] and trajectory scene keys.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "engine/error.hpp"
#include "engine/probe/indenter_shape.hpp"
#include "engine/sim/run.hpp"
#include "io/scene_file.hpp"
#include "tests/engine/probe/probe_fixtures.hpp"

namespace vb {
namespace {

constexpr double kH = 0.002;

TEST(Probing, ShapesSignedDistance) {
  IndenterSpec punch;
  punch.kind = IndenterSpec::Kind::Cylinder;
  punch.radius_m = 1;
  punch.normal = -Vec3::UnitZ();  // presses down; the body is above its face at z = 0
  const Vec3 o = Vec3::Zero();
  EXPECT_DOUBLE_EQ(indenter_signed_distance(punch, o, Vec3(0.5, 0, -2)), 2);      // below the face
  EXPECT_DOUBLE_EQ(indenter_signed_distance(punch, o, Vec3(3, 0, 5)), 2);         // beside the wall
  EXPECT_DOUBLE_EQ(indenter_signed_distance(punch, o, Vec3(4, 0, -4)), 5);        // off the rim: 3-4-5
  EXPECT_DOUBLE_EQ(indenter_signed_distance(punch, o, Vec3(0, 0.2, 0.1)), -0.1);  // inside, near the face
  EXPECT_DOUBLE_EQ(indenter_signed_distance(punch, o, Vec3(0.9, 0, 3)), -0.1 + 0 * 1e-16);  // inside, near the wall
  IndenterSpec finger;
  finger.kind = IndenterSpec::Kind::Capsule;
  finger.radius_m = 1;
  finger.length_m = 4;
  finger.normal = Vec3::UnitX();
  EXPECT_DOUBLE_EQ(indenter_signed_distance(finger, o, Vec3(2, 0, -3)), 2);   // beside the segment
  EXPECT_DOUBLE_EQ(indenter_signed_distance(finger, o, Vec3(-3, 0, 0)), 2);   // beyond the tip
  EXPECT_DOUBLE_EQ(indenter_signed_distance(finger, o, Vec3(7, 4, 0)), 4);    // beyond the far end: 3-4-5
}

TEST(Probing, TrajectoryDrivesTheIndenterThroughItsKnots) {
  Scene s = test::box_scene(10, 10, 6, kH);
  s.anchors.push_back(test::halfspace_anchor("base", Vec3(0, 0, kH), Vec3(0, 0, -1)));
  IndenterSpec ball;
  ball.kind = IndenterSpec::Kind::Sphere;
  ball.radius_m = 0.004;
  const double top = 5.5 * kH, x = 5 * kH;  // top element centres; a column between elements
  // down 2 mm into the block, across 4 mm, then up and away
  ball.path = {{0.00, Vec3(x, x, top + 0.004)}, {0.05, Vec3(x, x, top + 0.002)},
               {0.10, Vec3(x + 0.004, x, top + 0.002)}, {0.15, Vec3(x + 0.004, x, top + 0.010)}};
  ball.start_m = ball.path.front().position_m;
  s.indenters.push_back(ball);
  s.solver.damping_per_s = 50;
  s.solver.dashpot_ratio = 0.1;
  s.stop.equilibrium = 0;
  s.stop.max_time_s = 0.075;
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  EXPECT_TRUE(sim.indenter_position(0, 0.025).isApprox(Vec3(x, x, top + 0.003)));
  EXPECT_TRUE(sim.indenter_position(0, 0.2).isApprox(ball.path.back().position_m));
  const RunOutput mid = run_simulation(s, m.lattice, m.elements, sim);
  const Vec3 centre = sim.indenter_position(0, sim.time_s());
  EXPECT_NEAR((centre - Vec3(x + 0.002, x, top + 0.002)).norm(), 0, 1e-4) << "halfway across at t = 0.075 s";
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e) {
    const Vec3 p(mid.state.position_m[3 * e], mid.state.position_m[3 * e + 1], mid.state.position_m[3 * e + 2]);
    EXPECT_GE((p - centre).norm(), ball.radius_m * (1 - 1e-4)) << "element " << e << " inside the moving ball";
  }
  const Vec3 F = mid.summary.indenters[0].reaction_force_n;
  EXPECT_GT(F.z(), 0) << "pressed in: the tissue pushes the ball up";
  EXPECT_LT(F.x(), 0) << "dragged towards +x (frictionless): the tissue ahead pushes the ball back (−x)";

  // After the last knot the ball is 10 mm above the top and holds there: no contact.
  Simulator later(s, m.lattice, m.elements, test::cl_context());
  Scene s_end = s;
  s_end.stop.max_time_s = 0.3;
  const RunOutput end = run_simulation(s_end, m.lattice, m.elements, later);
  EXPECT_TRUE(later.indenter_position(0, later.time_s()).isApprox(ball.path.back().position_m));
  EXPECT_EQ(end.summary.indenters[0].contact_elements, 0);
}

TEST(Probing, CapsuleFingerPressesAlongItsLength) {
  Scene s = test::probe_block(16, 10, 8, kH, 3000);
  IndenterSpec finger;
  finger.kind = IndenterSpec::Kind::Capsule;
  finger.radius_m = 0.004;
  finger.length_m = 0.016;
  finger.normal = Vec3::UnitX();  // lying along x, its tip at the press point
  s.indenters.push_back(finger);
  s.probe = test::press_at(0.008, 0.010, 0.002, 2);
  const ProbeResult r = test::run_probe(s);
  const PressSample& last = r.presses.at(0).samples.back();
  EXPECT_GT(last.press_force_n, 0);
  // a line contact: more elements along x than across
  EXPECT_GE(last.contact_elements, 10);
  EXPECT_GT(last.contact_area_m2, 0);
}

TEST(Probing, GravitySettlesBeforeThePressStarts) {
  const int nz = 8;
  Scene s = test::probe_block(10, 10, nz, kH, 3000);
  IndenterSpec ball;
  ball.kind = IndenterSpec::Kind::Sphere;
  ball.radius_m = 0.004;
  s.indenters.push_back(ball);
  s.probe = test::press_at(5.5 * kH, 5.5 * kH, 0.001, 1);
  const ProbeResult without = test::run_probe(s);
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -9.81);
  const ProbeResult with = test::run_probe(s);
  EXPECT_TRUE(with.settled);
  // The press starts on the sagged surface: a column of length L under its own weight shortens by
  // ρgL²/(2E) (uniaxial stress; the held base and the free sides make it only approximate).
  const double L = (nz - 1) * kH, sag = 1000 * 9.81 * L * L / (2 * 3000);
  const double drop = without.presses[0].start_m.z() - with.presses[0].start_m.z();
  EXPECT_NEAR(drop / sag, 1.0, 0.25) << "drop " << drop << " m, column estimate " << sag << " m";
  EXPECT_NEAR(with.settle_max_displacement_m / sag, 1.0, 0.25);
  EXPECT_NEAR(with.presses[0].samples[0].press_force_n, 0, 1e-6) << "settled: the press starts at first touch";
}

TEST(Probing, SceneKeys) {
  const std::string dir = std::string(VOXBREAST_BINARY_DIR) + "/probe_scene_keys";
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/path.csv") << "time_s,x_mm,y_mm,z_mm\n0,0,0,30\n0.5,0,0,25\n1.0,10,0,25\n";
  const std::string head = "[model]\nspacing = 0.002\n[[model.shape]]\nkind = \"box\"\nmin = [0, 0, 0]\n"
                           "max = [0.02, 0.02, 0.02]\nlabel = \"fat\"\n[materials.fat]\nE = 1000.0\n";
  const Scene a = parse_scene_text(head +
                                       "[[indenter]]\nkind = \"capsule\"\nradius = 0.005\nlength = 0.02\naxis = [1, 0, 0]\n"
                                       "start = [0, 0, 0.03]\n[[indenter]]\nkind = \"cylinder\"\nradius = 0.004\n"
                                       "axis = [0, 0, -1]\npath = \"path.csv\"\n"
                                       "[probe]\nindenter = 1\nfrom = [0, 0.01, 0.03]\nto = [0.02, 0.01, 0.03]\n"
                                       "presses = 5\ndepth = 0.004\nsteps = 4\nat_force = [0.5, 1]\n",
                                   dir + "/scene.toml");
  ASSERT_EQ(a.indenters.size(), 2u);
  EXPECT_EQ(a.indenters[0].kind, IndenterSpec::Kind::Capsule);
  EXPECT_DOUBLE_EQ(a.indenters[0].length_m, 0.02);
  EXPECT_EQ(a.indenters[1].kind, IndenterSpec::Kind::Cylinder);
  ASSERT_EQ(a.indenters[1].path.size(), 3u);
  EXPECT_TRUE(a.indenters[1].path[2].position_m.isApprox(Vec3(0.01, 0, 0.025)));
  EXPECT_TRUE(a.probe.active);
  EXPECT_EQ(a.probe.indenter, 0u);
  EXPECT_EQ(a.probe.presses, 5);
  EXPECT_EQ(a.probe.at_force_n.size(), 2u);
  EXPECT_THROW(parse_scene_text(head + "[[indenter]]\nkind = \"capsule\"\nradius = 0.005\naxis = [1, 0, 0]\n"
                                       "start = [0, 0, 0.03]\n", dir + "/scene.toml"),
               Error);  // no length
  EXPECT_THROW(parse_scene_text(head + "[[indenter]]\nkind = \"plate\"\nnormal = [0, 0, 1]\nstart = [0, 0, 0]\n"
                                       "[probe]\nfrom = [0, 0, 0.03]\ndepth = 0.001\n", dir + "/scene.toml"),
               Error);  // a plate cannot probe a line
  std::ofstream(dir + "/bad.csv") << "time_s,x_mm,y_mm,z_mm\n0,0,0,30\n0,0,0,25\n";
  EXPECT_THROW(parse_scene_text(head + "[[indenter]]\nkind = \"sphere\"\nradius = 0.005\npath = \"bad.csv\"\n",
                                dir + "/scene.toml"),
               Error);  // times must increase
}

}  // namespace
}  // namespace vb
