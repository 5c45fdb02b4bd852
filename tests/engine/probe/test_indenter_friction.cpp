// Coulomb friction of a push indenter (`[[indenter]] friction`, docs/PROBING.md): a ball pressed
// into a block and slid sideways at constant depth. Once every contact element slips, the
// tangential reaction is μ times the normal one; with μ = 0 the forces are those of frictionless
// contact exactly, even with the friction code compiled in (another indenter has friction).
#include <gtest/gtest.h>

#include <cmath>

#include "engine/error.hpp"
#include "engine/sim/run.hpp"
#include "io/scene_file.hpp"
#include "tests/engine/probe/probe_fixtures.hpp"

namespace vb {
namespace {

constexpr double kH = 0.002, kR = 0.020, kDepth = 0.0005;

using Surface = IndenterSpec::Surface;

// A 32 × 20 × 12 mm block on a held base; a 20 mm ball pressed 0.5 mm in 0.05 s, then slid 8 mm
// along +x at 20 mm/s. `friction`: the ball's μ; `spare`: a second, distant indenter's μ;
// `surface`: the ball's contact surface.
Scene sliding_ball(double friction, double spare = -1, Surface surface = Surface::Vertices) {
  Scene s = test::box_scene(16, 10, 6, kH);
  s.anchors.push_back(test::halfspace_anchor("base", Vec3(0, 0, kH), Vec3(0, 0, -1)));
  s.solver.precision = Precision::Double;
  s.solver.damping_per_s = 50;
  s.solver.dashpot_ratio = 0.1;
  s.stop.equilibrium = 0;
  s.stop.max_time_s = 0.35;  // 6 mm along the slide
  IndenterSpec ball;
  ball.kind = IndenterSpec::Kind::Sphere;
  ball.radius_m = kR;
  ball.friction = friction;
  ball.contact_surface = surface;
  const double top = 5.5 * kH, x0 = 4 * kH, y = 5 * kH;  // top element centres; y between two columns
  ball.path = {{0.00, Vec3(x0, y, top + kR)}, {0.05, Vec3(x0, y, top + kR - kDepth)},
               {0.45, Vec3(x0 + 0.008, y, top + kR - kDepth)}};
  ball.start_m = ball.path.front().position_m;
  s.indenters.push_back(ball);
  if (spare >= 0) {
    IndenterSpec far;
    far.kind = IndenterSpec::Kind::Sphere;
    far.radius_m = 0.005;
    far.start_m = Vec3(0, 0, 1.0);
    far.friction = spare;  // vertex contact: a second triangle indenter would stiffen the stable step
    s.indenters.push_back(far);
  }
  return s;
}

RunOutput run(const Scene& s) {
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  return run_simulation(s, m.lattice, m.elements, sim);
}

TEST(Probing, SlidingBallFeelsCoulombFriction) {
  const double mu = 0.3;
  const RunOutput with = run(sliding_ball(mu));
  const RunOutput without = run(sliding_ball(0));
  const Vec3 F = with.summary.indenters[0].reaction_force_n, F0 = without.summary.indenters[0].reaction_force_n;
  const double ratio = -F.x() / F.z(), ratio0 = -F0.x() / F0.z();
  std::printf("sliding: F = (%.4g, %.4g, %.4g) N, tangential/normal %.4f (mu %.2f); frictionless (%.4g, %.4g, %.4g) N, %.4f; "
              "contact elements %lld\n",
              F.x(), F.y(), F.z(), ratio, mu, F0.x(), F0.y(), F0.z(), ratio0,
              (long long)with.summary.indenters[0].contact_elements);
  EXPECT_GT(F.z(), 0) << "pressed in";
  EXPECT_GT(with.summary.indenters[0].contact_elements, 4);
  EXPECT_NEAR(ratio, mu, 0.05 * mu) << "the ball drags the surface along +x: the tissue holds it back (−x)";
  EXPECT_LT(std::abs(ratio0), 0.02) << "frictionless: nearly no tangential force from a shallow ball";
  EXPECT_LT(std::abs(F.y()), 1e-6 * F.z()) << "symmetric about the slide's plane";
}

TEST(Probing, ZeroFrictionIsFrictionlessExactly) {
  // The second indenter's μ compiles the friction code in; the ball's μ = 0 must change nothing.
  const RunOutput plain = run(sliding_ball(0));
  const RunOutput compiled = run(sliding_ball(0, 0.3));
  const Vec3 a = plain.summary.indenters[0].reaction_force_n, b = compiled.summary.indenters[0].reaction_force_n;
  EXPECT_EQ(a.x(), b.x());
  EXPECT_EQ(a.y(), b.y());
  EXPECT_EQ(a.z(), b.z());
  EXPECT_EQ(plain.summary.indenters[0].contact_elements, compiled.summary.indenters[0].contact_elements);
  EXPECT_EQ(compiled.summary.indenters[1].contact_elements, 0);
}

// Triangle contact (contact_surface = "triangles", kernels/triangle_contact.cl): each element's
// share of the touching triangles' penalty forces is its normal force, and friction grips it as
// for vertex contact.
TEST(Probing, SlidingBallOnTrianglesFeelsCoulombFriction) {
  const double mu = 0.3;
  const RunOutput with = run(sliding_ball(mu, -1, Surface::Triangles));
  const RunOutput without = run(sliding_ball(0, -1, Surface::Triangles));
  const Vec3 F = with.summary.indenters[0].reaction_force_n, F0 = without.summary.indenters[0].reaction_force_n;
  const double ratio = -F.x() / F.z(), ratio0 = -F0.x() / F0.z();
  std::printf("sliding on triangles: F = (%.4g, %.4g, %.4g) N, tangential/normal %.4f (mu %.2f); frictionless "
              "(%.4g, %.4g, %.4g) N, %.4f; contact elements %lld\n",
              F.x(), F.y(), F.z(), ratio, mu, F0.x(), F0.y(), F0.z(), ratio0,
              (long long)with.summary.indenters[0].contact_elements);
  EXPECT_GT(F.z(), 0) << "pressed in";
  EXPECT_GT(with.summary.indenters[0].contact_elements, 4);
  EXPECT_NEAR(ratio, mu, 0.05 * mu) << "the tissue holds the ball back (−x)";
  EXPECT_LT(std::abs(ratio0), 0.02) << "frictionless: nearly no tangential force from a shallow ball";
  // The triangulation is not mirror-symmetric about the slide's plane (each square's diagonal
  // runs one way), so a small sideways force remains.
  EXPECT_LT(std::abs(F.y()), 0.02 * std::abs(F.x())) << "nearly symmetric about the slide's plane";
}

TEST(Probing, ZeroFrictionOnTrianglesIsFrictionlessExactly) {
  const RunOutput plain = run(sliding_ball(0, -1, Surface::Triangles));
  const RunOutput compiled = run(sliding_ball(0, 0.3, Surface::Triangles));
  const Vec3 a = plain.summary.indenters[0].reaction_force_n, b = compiled.summary.indenters[0].reaction_force_n;
  EXPECT_EQ(a.x(), b.x());
  EXPECT_EQ(a.y(), b.y());
  EXPECT_EQ(a.z(), b.z());
  EXPECT_EQ(plain.state.displacement_m, compiled.state.displacement_m);
  EXPECT_EQ(plain.summary.indenters[0].contact_elements, compiled.summary.indenters[0].contact_elements);
  EXPECT_EQ(compiled.summary.indenters[1].contact_elements, 0);
}

// Static friction on the triangles: the ball of sliding_ball pressed 0.5 mm, then dragged
// kDrag along +x in 0.05 s and held. The tangential load stays below μ·F_n, so the elements under
// the ball's centre stick to it and move with it (the drag's displacement, against the same press
// without the drag); frictionless they stay behind. Symplectic Euler here (Heun slides above).
constexpr double kDrag = 0.00005;

struct Drag {
  Vec3 force = Vec3::Zero();
  double force_x_mid = 0;  // F_x halfway through the hold (N)
  double shift_m = 0;      // mean x displacement of the top elements within 2 mm of the ball's axis
};

Drag drag(double friction, double distance) {
  Scene s = sliding_ball(friction, -1, Surface::Triangles);
  s.solver.integrator = Integrator::SymplecticEuler;
  s.stop.max_time_s = 0.25;
  const Vec3 pressed = s.indenters[0].path[1].position_m;
  s.indenters[0].path = {s.indenters[0].path[0], s.indenters[0].path[1], {0.10, pressed + Vec3(distance, 0, 0)}};
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  const RunOutput out = run_simulation(s, m.lattice, m.elements, sim);
  Drag d;
  d.force = out.summary.indenters[0].reaction_force_n;
  for (const auto& h : out.summary.indenters[0].history)
    if (h[0] <= 0.175) d.force_x_mid = h[1];
  const Vec3 axis = pressed + Vec3(distance, 0, 0);
  int count = 0;
  const auto& x = out.state.position_m;
  const auto& u = out.state.displacement_m;
  for (std::size_t e = 0; e < x.size() / 3; ++e) {
    const Vec3 rest(x[3 * e] - u[3 * e], x[3 * e + 1] - u[3 * e + 1], x[3 * e + 2] - u[3 * e + 2]);
    if (rest.z() < 5 * kH || std::hypot(rest.x() - axis.x(), rest.y() - axis.y()) > kH + 1e-9) continue;  // 2 mm
    d.shift_m += u[3 * e];
    ++count;
  }
  EXPECT_GT(count, 0);
  d.shift_m /= std::max(count, 1);
  return d;
}

TEST(Probing, SmallDragOnTrianglesSticks) {
  const double mu = 0.3;
  const Drag held = drag(mu, kDrag), pressed = drag(mu, 0), slipped = drag(0, kDrag), slipped0 = drag(0, 0);
  const double ratio = -held.force.x() / held.force.z();
  const double stick = (held.shift_m - pressed.shift_m) / kDrag, slip = (slipped.shift_m - slipped0.shift_m) / kDrag;
  std::printf("drag %.3f mm on triangles: F = (%.4g, %.4g, %.4g) N, tangential/normal %.4f (mu %.2f), F_x mid-hold %.4g N; "
              "centre elements moved %.3f of the drag (frictionless %.3f)\n",
              1e3 * kDrag, held.force.x(), held.force.y(), held.force.z(), ratio, mu, held.force_x_mid, stick, slip);
  EXPECT_GT(ratio, 0.05) << "the tissue holds the ball back";
  EXPECT_LT(ratio, 0.8 * mu) << "a tangential load below the Coulomb limit";
  EXPECT_NEAR(stick, 1.0, 0.1) << "the elements under the ball move with it";
  EXPECT_LT(std::abs(slip), 0.2) << "frictionless: the ball slides over them";
  EXPECT_NEAR(held.force_x_mid, held.force.x(), 0.02 * std::abs(held.force.x())) << "held, not creeping";
}

TEST(Probing, FrictionKey) {
  const std::string head = "[model]\nspacing = 0.002\n[[model.shape]]\nkind = \"box\"\nmin = [0, 0, 0]\n"
                           "max = [0.02, 0.02, 0.02]\nlabel = \"fat\"\n[materials.fat]\nE = 1000.0\n"
                           "[[indenter]]\nkind = \"sphere\"\nradius = 0.005\nstart = [0, 0, 0.03]\n";
  EXPECT_DOUBLE_EQ(parse_scene_text(head + "friction = 0.3\n", "s.toml").indenters[0].friction, 0.3);
  EXPECT_DOUBLE_EQ(parse_scene_text(head, "s.toml").indenters[0].friction, 0.0);
  EXPECT_THROW(parse_scene_text(head + "friction = -0.1\n", "s.toml"), Error);
  EXPECT_THROW(parse_scene_text(head + "friction = 0.3\ncontact = \"slide\"\n", "s.toml"), Error);
  EXPECT_THROW(parse_scene_text(head + "friction = 0.3\ncontact = \"stick\"\n", "s.toml"), Error);
}

}  // namespace
}  // namespace vb
