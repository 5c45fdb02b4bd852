// Indenter contact with the surface triangles (`contact_surface = "triangles"`, docs/PROBING.md,
// kernels/triangle_contact.cl): a point probe (a sphere below the spacing) between the vertices
// feels the surface where vertex contact feels nothing; the forces are split by barycentric weights
// and sum to the indenter's reaction; a sphere still follows Hertz; scenes without it build none of it.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/error.hpp"
#include "engine/sim/time_step.hpp"
#include "io/scene_file.hpp"
#include "tests/engine/probe/probe_fixtures.hpp"

namespace vb {
namespace {

constexpr double kH = 0.002, kE = 3000;
constexpr int kN = 10, kNz = 6;
const double kTop = (kNz - 0.5) * kH;  // the top face: the top layer's element centres

IndenterSpec point_probe(double radius, IndenterSpec::Surface surface = IndenterSpec::Surface::Triangles) {
  IndenterSpec p;
  p.kind = IndenterSpec::Kind::Sphere;
  p.radius_m = radius;
  p.contact_surface = surface;
  p.start_m = Vec3(0, 0, 1.0);  // far above until placed
  return p;
}

Scene probe_scene(const IndenterSpec& probe, Precision precision = Precision::Double) {
  Scene s = test::probe_block(kN, kN, kNz, kH, kE);
  s.solver.precision = precision;
  s.indenters.push_back(probe);
  return s;
}

// Top-face square with its lower corner at the element centre (x0, y0): its triangle
// (x0, y0), (x0 + h, y0), (x0 + h, y0 + h) (the diagonal runs from the lowest corner) has its
// centroid at (x0 + 2h/3, y0 + h/3).
const double kX0 = 4.5 * kH, kY0 = 4.5 * kH;

struct Touch {
  int triangles = 0;          // triangles with a force
  Vec3 total = Vec3::Zero();  // on the tissue
  std::vector<Vec3> corners;  // the corner forces of the touched triangles
};

// Corner forces of Simulator::triangle_contact_forces_n (indenter 0).
Touch touched(const std::vector<double>& f) {
  Touch t;
  for (std::size_t tr = 0; tr < f.size() / 9; ++tr) {
    Vec3 c[3];
    double size = 0;
    for (int k = 0; k < 3; ++k) c[k] = Vec3(f[9 * tr + 3 * k], f[9 * tr + 3 * k + 1], f[9 * tr + 3 * k + 2]), size += c[k].norm();
    if (size == 0) continue;
    ++t.triangles;
    for (const Vec3& v : c) t.total += v, t.corners.push_back(v);
  }
  return t;
}

TEST(TriangleContact, ForcesSplitByBarycentricWeights) {
  const double r = 0.25 * kH, depth = 0.1 * r;
  const Scene s = probe_scene(point_probe(r));
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  ASSERT_TRUE(sim.triangle_contact());
  const double kp = sim.contact_stiffness_n_m()[0];
  ASSERT_GT(kp, 0);
  const double F = kp * depth;

  // Over a triangle's centroid: one triangle, three equal shares, pushing down.
  sim.place_indenter(0, Vec3(kX0 + 2 * kH / 3, kY0 + kH / 3, kTop + r - depth));
  Touch t = touched(sim.triangle_contact_forces_n());
  ASSERT_EQ(t.triangles, 1);
  EXPECT_NEAR(t.total.z(), -F, 1e-12 * F);
  for (const Vec3& c : t.corners) {
    EXPECT_NEAR(c.z(), -F / 3, 1e-12 * F);
    EXPECT_LT(std::hypot(c.x(), c.y()), 1e-12 * F);
  }
  StateCheck check = sim.check();
  EXPECT_NEAR(check.indenter_force_n[0].z(), F, 1e-12 * F) << "the reaction is minus the sum of the vertex forces";
  EXPECT_EQ(check.contact_elements[0], 3);

  // Over a vertex (an element centre): each of its six triangles reaches it there and gives it
  // the whole of its force (weights 1, 0, 0): the vertex carries all of it, six times k_p·δ (the
  // penalty is stiffer at a vertex; the force of a relaxed press is still the tissue's).
  sim.place_indenter(0, Vec3(kX0, kY0, kTop + r - depth));
  t = touched(sim.triangle_contact_forces_n());
  ASSERT_EQ(t.triangles, 6);
  int loaded = 0;
  for (const Vec3& c : t.corners)
    if (c.norm() > 1e-9 * F) {
      ++loaded;
      EXPECT_NEAR(c.z(), -F, 1e-9 * F);
    }
  EXPECT_EQ(loaded, 6);
  check = sim.check();
  EXPECT_NEAR(check.indenter_force_n[0].z(), 6 * F, 1e-9 * F);
  EXPECT_NEAR(t.total.z(), -6 * F, 1e-9 * F);
  EXPECT_EQ(check.contact_elements[0], 1) << "one element carries it";

  // Over the middle of an edge: its two triangles, each half to either end.
  sim.place_indenter(0, Vec3(kX0 + 0.5 * kH, kY0, kTop + r - depth));
  t = touched(sim.triangle_contact_forces_n());
  ASSERT_EQ(t.triangles, 2);
  loaded = 0;
  for (const Vec3& c : t.corners)
    if (c.norm() > 1e-9 * F) {
      ++loaded;
      EXPECT_NEAR(c.z(), -F / 2, 1e-9 * F);
    }
  EXPECT_EQ(loaded, 4);
  check = sim.check();
  EXPECT_NEAR(check.indenter_force_n[0].z(), 2 * F, 1e-9 * F);

  // Above the surface: nothing.
  sim.place_indenter(0, Vec3(kX0 + 2 * kH / 3, kY0 + kH / 3, kTop + 1.01 * r));
  EXPECT_EQ(touched(sim.triangle_contact_forces_n()).triangles, 0);
  EXPECT_EQ(sim.check().contact_elements[0], 0);
}

/// Force–depth samples of a point probe pressed at (x, y) from z = top + r (the flat face's first
/// touch), after each increment relaxed; `sum_ok`: the reaction equals minus the sum of the vertex
/// forces in the final (deformed) state.
struct Press {
  std::vector<double> depth_mm, force_n;
  double reaction_vs_sum = 0;  // |F_reaction + Σ f_vertex| / |F_reaction|
};

Press press(IndenterSpec::Surface surface, double x, double y, double r, double depth, int steps) {
  Scene s = probe_scene(point_probe(r, surface));
  s.probe = test::press_at(x, y, depth, steps);
  s.probe.from_m = s.probe.to_m = Vec3(x, y, kTop + r);
  s.probe.from_contact = false;
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  const ProbeResult res = run_press_line(s, m.lattice, m.elements, sim);
  EXPECT_EQ(res.unconverged_increments, 0);
  Press p;
  for (const PressSample& q : res.presses.at(0).samples) p.depth_mm.push_back(1e3 * q.depth_m), p.force_n.push_back(q.press_force_n);
  if (sim.triangle_contact()) {
    const Vec3 reaction = sim.check().indenter_force_n[0];
    p.reaction_vs_sum = (reaction + touched(sim.triangle_contact_forces_n()).total).norm() / reaction.norm();
  }
  return p;
}

TEST(TriangleContact, PointProbeBetweenVerticesFeelsTheSurface) {
  const double r = 0.25 * kH, depth = 0.5 * kH;
  const int steps = 4;
  const double cx = kX0 + 2 * kH / 3, cy = kY0 + kH / 3;
  const Press tri = press(IndenterSpec::Surface::Triangles, cx, cy, r, depth, steps);
  const Press vert = press(IndenterSpec::Surface::Vertices, cx, cy, r, depth, steps);
  const Press tri_v = press(IndenterSpec::Surface::Triangles, kX0, kY0, r, depth, steps);
  const Press vert_v = press(IndenterSpec::Surface::Vertices, kX0, kY0, r, depth, steps);
  for (int j = 0; j <= steps; ++j)
    std::printf("point probe r %.2f mm  depth %.3f mm  centroid: triangles %.4g N vertices %.4g N  "
                "vertex: triangles %.4g N vertices %.4g N (ratio %.3f)\n",
                1e3 * r, tri.depth_mm[j], tri.force_n[j], vert.force_n[j], tri_v.force_n[j], vert_v.force_n[j],
                vert_v.force_n[j] > 0 ? tri_v.force_n[j] / vert_v.force_n[j] : 0.0);
  for (int j = 1; j <= steps; ++j) {
    EXPECT_EQ(vert.force_n[j], 0) << "between the vertices the probe slips through vertex contact";
    EXPECT_GT(tri.force_n[j], tri.force_n[j - 1]) << "triangle contact: the force grows with depth";
    EXPECT_GT(tri_v.force_n[j], tri_v.force_n[j - 1]);
  }
  // Over a vertex both first press that one element and agree (the penalty's penetration F/k_p
  // against the neighbouring triangles the ball meets as the vertex sinks). Deeper, vertex
  // contact loses the element: it slides off the small ball sideways (docs/VALIDATION.md).
  EXPECT_NEAR(tri_v.force_n[1] / vert_v.force_n[1], 1.0, 0.1);
  EXPECT_LT(tri.reaction_vs_sum, 1e-9) << "reaction = −Σ vertex forces";
  EXPECT_LT(tri_v.reaction_vs_sum, 1e-9);
}

// The Hertz check of test_hertz_contact.cpp with the ball on the triangles, at the default
// penalty and the vertex test's float model and 1e-6 equilibrium. The faces between the vertices
// dip into a sphere through them by up to the sagitta s = h²/(4R) (0.056 mm here), so triangle
// contact, which keeps the faces out of the ball, presses the vertices deeper than vertex contact:
// with a rigid penalty it is vertex contact of a ball of radius R + s at the same centre. The
// penalty's own compliance keeps it below that (docs/VALIDATION.md, "Probing: palpation and indenters").
struct HertzPress {
  std::vector<double> depth_m, force_n;
  Vec3 last_force_n = Vec3::Zero();
  int unconverged = 0;
};

HertzPress hertz_press(double radius, IndenterSpec::Surface surface, double zero_z) {
  const double h = 0.002;
  const int n = 25, nz = 20;
  Scene s = test::probe_block(n, n, nz, h, kE);
  s.indenters.push_back(point_probe(radius, surface));
  s.stop.max_steps = 3000;
  s.probe = test::press_at(0.5 * n * h, 0.5 * n * h, 1.0 * h, 2);  // over an element column, 1 mm increments
  s.probe.from_contact = false;  // every ball at the same centres
  s.probe.from_m = s.probe.to_m = Vec3(0.5 * n * h, 0.5 * n * h, zero_z);
  const ProbeResult r = test::run_probe(s);
  HertzPress p;
  p.unconverged = int(r.unconverged_increments);
  for (const PressSample& q : r.presses.at(0).samples) {
    p.depth_m.push_back(q.depth_m), p.force_n.push_back(q.press_force_n), p.last_force_n = q.force_n;
    std::printf("hertz press  R %.4f mm  %s  depth %.3f mm  F %.5g N  contact %lld  area %.2f mm2  steps %lld residual %.3g\n",
                1e3 * radius, surface == IndenterSpec::Surface::Triangles ? "triangles" : "vertices", 1e3 * q.depth_m,
                q.press_force_n, (long long)q.contact_elements, 1e6 * q.contact_area_m2, (long long)q.steps, q.residual);
  }
  return p;
}

TEST(TriangleContact, SphereOnTrianglesFollowsHertz) {
  const double h = 0.002, Estar = kE * 16 / 15, R = 9 * h, s = h * h / (4 * R);
  const double zero_z = 19.5 * h + R;  // the ball touches the top layer's centres
  const HertzPress tri = hertz_press(R, IndenterSpec::Surface::Triangles, zero_z);
  const HertzPress vert = hertz_press(R, IndenterSpec::Surface::Vertices, zero_z);
  const HertzPress vert_s = hertz_press(R + s, IndenterSpec::Surface::Vertices, zero_z);
  EXPECT_EQ(tri.unconverged, 0) << "relaxation reaches 1e-6 with the penalty at its default stiffness";
  for (std::size_t j = 1; j < tri.depth_m.size(); ++j) {
    const double d = tri.depth_m[j];
    const double hertz = 4.0 / 3 * Estar * std::sqrt(R) * std::pow(d, 1.5);
    const double hertz_s = 4.0 / 3 * Estar * std::sqrt(R + s) * std::pow(d + s, 1.5);
    std::printf("hertz (triangles) depth %.3f mm  F %.5g N  Hertz %.5g N (ratio %.3f)  Hertz of R + s at depth + s "
                "%.5g N (ratio %.3f)  vertex contact R %.5g N, R + s %.5g N  (share of the sagitta gap %.2f)\n",
                1e3 * d, tri.force_n[j], hertz, tri.force_n[j] / hertz, hertz_s, tri.force_n[j] / hertz_s,
                vert.force_n[j], vert_s.force_n[j], (tri.force_n[j] - vert.force_n[j]) / (vert_s.force_n[j] - vert.force_n[j]));
    EXPECT_NEAR(tri.force_n[j] / hertz_s, 1.0, 0.10) << "at depth " << d << " m";
    // Stiffer than vertex contact by most of the sagitta's share, softer than its rigid limit.
    EXPECT_GT(tri.force_n[j], vert.force_n[j] + 0.5 * (vert_s.force_n[j] - vert.force_n[j])) << "at depth " << d;
    EXPECT_LT(tri.force_n[j], vert_s.force_n[j]) << "at depth " << d;
  }
  const Vec3 F = tri.last_force_n;
  EXPECT_LT(std::hypot(F.x(), F.y()), 1e-3 * F.z());
}

TEST(TriangleContact, BuiltOnlyWhenAnIndenterUsesIt) {
  const auto kernels = [](const Simulator& sim) { return sim.program().getInfo<CL_PROGRAM_KERNEL_NAMES>(); };
  const Scene plain = probe_scene(point_probe(0.25 * kH, IndenterSpec::Surface::Vertices), Precision::Float);
  const Scene tri = probe_scene(point_probe(0.25 * kH), Precision::Float);
  const auto m = test::make_model(plain);
  Simulator a(plain, m.lattice, m.elements, test::cl_context());
  Simulator b(tri, m.lattice, m.elements, test::cl_context());
  EXPECT_FALSE(a.triangle_contact());
  EXPECT_EQ(kernels(a).find("triangle_contact"), std::string::npos) << kernels(a);
  EXPECT_NE(kernels(b).find("triangle_contact"), std::string::npos) << kernels(b);
  EXPECT_GT(b.device_bytes(), a.device_bytes());
  EXPECT_THROW(a.triangle_contact_forces_n(), Error);
  EXPECT_EQ(a.contact_stiffness_n_m()[0], 0);
}

TEST(TriangleContact, PenaltyEntersTheStableStep) {
  Scene plain = probe_scene(point_probe(0.25 * kH, IndenterSpec::Surface::Vertices));
  Scene tri = probe_scene(point_probe(0.25 * kH));
  const auto m = test::make_model(plain);
  // Relaxation: the step stays, the surface elements' fictitious masses grow instead.
  EXPECT_EQ(choose_time_step(plain, m.lattice, m.elements).dt_s, choose_time_step(tri, m.lattice, m.elements).dt_s);
  for (Scene* s : {&plain, &tri}) s->solver.integrator = Integrator::SymplecticEuler;
  const double dt_plain = choose_time_step(plain, m.lattice, m.elements).dt_s;
  const double dt_tri = choose_time_step(tri, m.lattice, m.elements).dt_s;
  std::printf("symplectic Euler dt: vertex contact %.4g s, triangle contact %.4g s\n", dt_plain, dt_tri);
  EXPECT_LT(dt_tri, dt_plain);
}

TEST(TriangleContact, SceneKeys) {
  const std::string head = "[model]\nspacing = 0.002\n[[model.shape]]\nkind = \"box\"\nmin = [0, 0, 0]\n"
                           "max = [0.02, 0.02, 0.02]\nlabel = \"fat\"\n[materials.fat]\nE = 1000.0\n"
                           "[[indenter]]\nstart = [0, 0, 0.03]\n";
  const std::string sphere = head + "kind = \"sphere\"\nradius = 0.0005\n";
  EXPECT_EQ(parse_scene_text(sphere, "s.toml").indenters[0].contact_surface, IndenterSpec::Surface::Vertices);
  const Scene s = parse_scene_text(sphere + "contact_surface = \"triangles\"\ncontact_stiffness = 2.5\n", "s.toml");
  EXPECT_EQ(s.indenters[0].contact_surface, IndenterSpec::Surface::Triangles);
  EXPECT_DOUBLE_EQ(s.indenters[0].contact_stiffness, 2.5);
  EXPECT_THROW(parse_scene_text(sphere + "contact_surface = \"edges\"\n", "s.toml"), Error);
  EXPECT_THROW(parse_scene_text(sphere + "contact_stiffness = 2\n", "s.toml"), Error) << "only with triangles";
  EXPECT_DOUBLE_EQ(parse_scene_text(sphere + "contact_surface = \"triangles\"\nfriction = 0.3\n", "s.toml").indenters[0].friction,
                   0.3)
      << "Coulomb friction is built for triangle contact (test_indenter_friction.cpp)";
  EXPECT_THROW(parse_scene_text(sphere + "contact_surface = \"triangles\"\ncontact = \"stick\"\n", "s.toml"), Error);
  EXPECT_THROW(parse_scene_text(head + "kind = \"plate\"\nnormal = [0, 0, -1]\ncontact_surface = \"triangles\"\n", "s.toml"),
               Error);
  EXPECT_THROW(parse_scene_text(head + "kind = \"cylinder\"\nradius = 0.002\naxis = [0, 0, -1]\n"
                                       "contact_surface = \"triangles\"\n", "s.toml"),
               Error);
}

}  // namespace
}  // namespace vb
