// Hyperelastic element stresses on the device: against the double host reference, consistency
// (rigid motion, total force and torque), homogeneous states against closed forms, and
// hourglass control.
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "engine/material/hyperelastic.hpp"
#include "engine/sim/host_reference.hpp"
#include "engine/sim/simulator.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"
#include "tests/engine/sim/trajectory_compare.hpp"

namespace vb {
namespace {

MaterialSpec neo_hookean(double E, double nu) {
  MaterialSpec m = test::material("soft", E);
  m.law = "neo-hookean";
  m.poisson_ratio = nu;
  return m;
}

MaterialSpec ogden_two_term() {
  MaterialSpec m = test::material("soft", 0);
  m.law = "ogden";
  m.ogden_mu_pa = {1200, -300};
  m.ogden_alpha = {4, -2};
  m.poisson_ratio = 0.49;
  return m;
}

/// n × n × n block of one hyperelastic material (no gravity, no damping).
Scene hyper_block(int n, const MaterialSpec& material, Precision precision = Precision::Double) {
  Scene s = test::box_scene(n, n, n, 0.002);
  s.materials["soft"] = material;
  s.materials["soft"].name = "soft";
  s.solver.precision = precision;
  s.solver.dashpot_ratio = 0;
  s.solver.dt_s = 1e-5;  // force evaluations only: no step is taken
  return s;
}

std::vector<double> field(const Lattice& lat, const std::function<Vec3(const Vec3&)>& u) {
  std::vector<double> out(3 * lat.element_count());
  for (std::size_t e = 0; e < lat.element_count(); ++e) {
    const Vec3 x = u(lat.rest_position(e));
    for (int c = 0; c < 3; ++c) out[3 * e + c] = x[c];
  }
  return out;
}

std::vector<double> device_forces(const Scene& s, const test::Model& m, const std::vector<double>& u) {
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  sim.upload(u, std::vector<double>(u.size(), 0.0));
  return sim.lattice_forces();
}

double max_abs(const std::vector<double>& a) {
  double r = 0;
  for (double x : a) r = std::max(r, std::abs(x));
  return r;
}

TEST(HyperelasticKernels, MatchHostReferenceAcrossLawsAndAnInterface) {
  Scene s = hyper_block(6, neo_hookean(3000, 0.45));
  ShapeSpec inclusion;
  inclusion.kind = ShapeSpec::Kind::Sphere;
  inclusion.center_m = Vec3(0.006, 0.006, 0.006);
  inclusion.radius_m = 0.0035;
  inclusion.label = "tumour";
  s.model.shapes.push_back(inclusion);
  s.materials["tumour"] = ogden_two_term();
  s.materials["tumour"].name = "tumour";
  ShapeSpec slab = s.model.shapes[0];
  slab.max_m.z() = 0.002;  // a linear-spring layer at the bottom: spring/hyperelastic interface
  slab.label = "springs";
  s.model.shapes.push_back(slab);
  s.materials["springs"] = test::material("springs", 5000);
  s.solver.dashpot_ratio = 0.2;
  for (Precision p : {Precision::Double, Precision::Float}) {
    s.solver.precision = p;
    const test::Model m = test::make_model(s);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> r(-1, 1);
    std::vector<double> u(3 * m.lattice.element_count()), v(u.size());
    for (std::size_t i = 0; i < u.size(); ++i) u[i] = 0.1 * 0.002 * r(rng), v[i] = 0.01 * r(rng);
    Simulator sim(s, m.lattice, m.elements, test::cl_context());
    sim.upload(u, v);
    const auto f_dev = sim.lattice_forces();
    const auto f_host = HostReference(m.lattice, m.elements, s).lattice_forces(u, v);
    double diff = 0;
    for (std::size_t i = 0; i < u.size(); ++i) diff = std::max(diff, std::abs(f_dev[i] - f_host[i]));
    EXPECT_LE(diff / max_abs(f_host), p == Precision::Double ? 1e-9 : 1e-4) << (p == Precision::Double ? "double" : "float");
  }
}

TEST(HyperelasticKernels, RigidRotationGivesNoForce) {
  const Scene s = hyper_block(5, ogden_two_term());
  const test::Model m = test::make_model(s);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vec3(1, 2, -1).normalized()).toRotationMatrix();
  const Vec3 c(0.005, 0.005, 0.005);
  const auto rotated = device_forces(s, m, field(m.lattice, [&](const Vec3& X) { return Vec3(R * (X - c) + c - X); }));
  const auto stretched = device_forces(s, m, field(m.lattice, [&](const Vec3& X) { return Vec3(0.05 * (X - c)); }));
  EXPECT_LT(max_abs(rotated), 1e-9 * max_abs(stretched));
}

TEST(HyperelasticKernels, InternalForcesHaveNoNetForceOrTorque) {
  const Scene s = hyper_block(5, neo_hookean(3000, 0.49));
  const test::Model m = test::make_model(s);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> r(-1, 1);
  std::vector<double> u(3 * m.lattice.element_count());
  for (double& x : u) x = 0.2 * 0.002 * r(rng);
  const auto f = device_forces(s, m, u);
  Vec3 total = Vec3::Zero(), torque = Vec3::Zero();
  double scale = 0;
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e) {
    const Vec3 fe(f[3 * e], f[3 * e + 1], f[3 * e + 2]);
    const Vec3 x = m.lattice.rest_position(e) + Vec3(u[3 * e], u[3 * e + 1], u[3 * e + 2]);
    total += fe;
    torque += x.cross(fe);
    scale += fe.norm();
  }
  EXPECT_LT(total.norm(), 1e-10 * scale);
  EXPECT_LT(torque.norm(), 1e-10 * scale * 0.01);  // lever arms ~1 cm
}

// The device's elastic forces are the negative gradient of the host's energy (an independent
// implementation: Σ w_e·h³·W_iso(F_e) plus the dual cells' h³·κ_c/2·(J_c − 1)², exact trilinear
// cell volumes), by central differences, with the hourglass springs off (they have no energy) and
// two laws whose bulk moduli differ, so cells across the interface average them.
TEST(HyperelasticKernels, ForcesAreTheNegativeGradientOfTheEnergy) {
  Scene s = hyper_block(5, neo_hookean(3000, 0.499));
  ShapeSpec inclusion;
  inclusion.kind = ShapeSpec::Kind::Sphere;
  inclusion.center_m = Vec3(0.004, 0.004, 0.004);
  inclusion.radius_m = 0.0025;
  inclusion.label = "tumour";
  s.model.shapes.push_back(inclusion);
  s.materials["tumour"] = ogden_two_term();
  s.materials["tumour"].name = "tumour";
  s.solver.hourglass = 0;
  const test::Model m = test::make_model(s);
  std::mt19937 rng(19);
  std::uniform_real_distribution<double> r(-1, 1);
  std::vector<double> u(3 * m.lattice.element_count());
  for (double& x : u) x = 0.15 * 0.002 * r(rng);
  const auto f = device_forces(s, m, u);
  const HostReference host(m.lattice, m.elements, s);
  const double step = 1e-7 * 0.002, scale = max_abs(f);
  std::uniform_int_distribution<std::size_t> pick(0, u.size() - 1);
  for (int sample = 0; sample < 40; ++sample) {
    const std::size_t i = pick(rng);
    std::vector<double> plus = u, minus = u;
    plus[i] += step;
    minus[i] -= step;
    const double gradient = (host.elastic_energy(plus) - host.elastic_energy(minus)) / (2 * step);
    EXPECT_NEAR(f[i], -gradient, 1e-6 * scale) << "element " << i / 3 << " component " << i % 3;
  }
}

// Under a homogeneous compression every dual cell has the element's J, so the volumetric forces
// are the pressure times the hull's area on the surface and vanish inside; a non-affine state of
// the same boundary (interior elements swirled) keeps the cells' total volume, so it cannot lower
// the volumetric energy below the homogeneous state's the way per-element volumes could.
TEST(HyperelasticKernels, CellVolumesAddUpToTheBodyVolume) {
  const Scene s = hyper_block(6, neo_hookean(3000, 0.499));
  const test::Model m = test::make_model(s);
  const HostReference host(m.lattice, m.elements, s);
  const auto squeezed = field(m.lattice, [](const Vec3& X) { return Vec3(0, 0, -0.1 * X.z()); });
  auto swirled = squeezed;
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e) {
    const auto ijk = m.lattice.voxel_ijk(e);
    if (std::min({ijk[0], ijk[1], ijk[2], 5 - ijk[0], 5 - ijk[1], 5 - ijk[2]}) == 0) continue;  // boundary stays
    const double a = 0.3 * 0.002 * ((ijk[0] + ijk[1] + ijk[2]) % 2 ? 1 : -1);
    swirled[3 * e] += a * (ijk[1] - 2.5) / 2.5;
    swirled[3 * e + 1] -= a * (ijk[0] - 2.5) / 2.5;
  }
  // the isochoric energy rises (non-affine), the volumetric one is that of the whole box at J = 0.9
  // spread over the cells: at least the homogeneous state's (Jensen), whatever the interior does
  Scene volumetric_only = s;
  volumetric_only.materials["soft"].poisson_ratio = 0.4999999;
  const test::Model mv = test::make_model(volumetric_only);
  const HostReference hv(mv.lattice, mv.elements, volumetric_only);
  EXPECT_GE(hv.elastic_energy(swirled), hv.elastic_energy(squeezed) * (1 - 1e-9));
  const auto f = device_forces(s, m, squeezed);
  double interior = 0, scale = max_abs(f);
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e) {
    const auto ijk = m.lattice.voxel_ijk(e);
    if (std::min({ijk[0], ijk[1], ijk[2], 5 - ijk[0], 5 - ijk[1], 5 - ijk[2]}) >= 2)
      interior = std::max(interior, Vec3(f[3 * e], f[3 * e + 1], f[3 * e + 2]).norm());
  }
  EXPECT_LT(interior, 1e-9 * scale) << "a homogeneous state loads only the surface layers";
}

struct Uniaxial {
  const char* law;
  double stretch;
};

class HomogeneousUniaxial : public ::testing::TestWithParam<Uniaxial> {};

/// A free 8³ block given the exact uniaxial-stress state F = diag(λt, λt, λ). The end layers carry
/// the load, along z, so plates can hold the state: every other layer is in equilibrium, and so is
/// every element two or more layers from the lateral faces (near the ends, the outer two columns
/// exchange a self-balancing force: an edge element's one-sided fit couples x and z). The force the
/// upper half exerts across the mid-plane over the body's area (the hull of the element centres,
/// 7h × 7h) is the nominal stress.
TEST_P(HomogeneousUniaxial, NominalStressMatchesClosedForm) {
  const Uniaxial c = GetParam();
  const MaterialSpec material = std::string(c.law) == "ogden" ? ogden_two_term() : neo_hookean(3000, 0.499);
  const Scene s = hyper_block(8, material);
  const test::Model m = test::make_model(s);
  const HyperelasticLaw law = law_of(s.materials.at("soft"));
  double lo = 0.3, hi = 3.0;  // lateral stretch with zero lateral stress
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    (first_piola(law, Vec3(mid, mid, c.stretch).asDiagonal())(0, 0) > 0 ? hi : lo) = mid;
  }
  const double lateral = 0.5 * (lo + hi);
  const auto f = device_forces(s, m, field(m.lattice, [&](const Vec3& X) {
    return Vec3((lateral - 1) * X.x(), (lateral - 1) * X.y(), (c.stretch - 1) * X.z());
  }));
  double section_force = 0, off_end = 0, sideways = 0;
  std::array<double, 8> layer_force{};
  std::array<Eigen::Vector2d, 8> layer_sideways;
  for (auto& l : layer_sideways) l.setZero();
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e) {
    const auto ijk = m.lattice.voxel_ijk(e);
    if (ijk[2] >= 4) section_force += f[3 * e + 2];
    const Vec3 fe(f[3 * e], f[3 * e + 1], f[3 * e + 2]);
    layer_force[ijk[2]] += fe.z();
    layer_sideways[ijk[2]] += fe.head<2>();
    const bool near_lateral_face = std::min({ijk[0], ijk[1], 7 - ijk[0], 7 - ijk[1]}) < 2;
    if (ijk[2] != 0 && ijk[2] != 7 && !near_lateral_face) off_end = std::max(off_end, fe.norm());
    // The isochoric stress (per element, least-squares fit) and the volumetric one (dual cells)
    // each put their stress times the hull's area on the lateral faces, which cancel, but the
    // fit's elements along an edge of the block, one-sided in two directions, also exchange a
    // self-balancing force with the next layer in (PHYSICS.md, "Element volume"), which the cells
    // do not: sideways forces only within two layers of an edge.
    int near_faces = 0;
    for (int a = 0; a < 3; ++a) near_faces += std::min(ijk[a], 7 - ijk[a]) < 2;
    if (near_faces < 2) sideways = std::max(sideways, fe.head<2>().norm());
  }
  const double area = 7 * 7 * 0.002 * 0.002;
  const double nominal = -section_force / area;  // the body pulls a stretched end back
  const double scale = std::abs(section_force) / 64;  // a typical end-element force
  EXPECT_LT(off_end, 1e-9 * scale) << "interior elements off the ends are in equilibrium";
  for (int k = 1; k < 7; ++k) EXPECT_LT(std::abs(layer_force[k]), 1e-9 * scale) << "layer " << k;
  EXPECT_LT(sideways, 1e-9 * scale) << "forces are along z away from the block's edges";
  for (int k = 0; k < 8; ++k)
    EXPECT_LT(layer_sideways[k].norm(), 1e-9 * scale) << "layer " << k << ": the edges' sideways forces self-balance";
  const double exact = uniaxial_nominal_stress(law, c.stretch);
  RecordProperty(std::string(c.law) + "_" + std::to_string(c.stretch), std::to_string(nominal / exact));
  EXPECT_NEAR(nominal / exact, 1.0, 0.03) << c.law << " λ = " << c.stretch << ": " << nominal << " vs " << exact;
}

INSTANTIATE_TEST_SUITE_P(Stretches, HomogeneousUniaxial,
                         ::testing::Values(Uniaxial{"neo_hookean", 0.5}, Uniaxial{"neo_hookean", 0.7},
                                           Uniaxial{"neo_hookean", 0.9}, Uniaxial{"neo_hookean", 1.3},
                                           Uniaxial{"ogden", 0.5}, Uniaxial{"ogden", 0.7}, Uniaxial{"ogden", 0.9},
                                           Uniaxial{"ogden", 1.3}),
                         [](const auto& info) {  // e.g. ogden_stretch_130
                           return std::string(info.param.law) + "_stretch_" +
                                  std::to_string(int(std::lround(100 * info.param.stretch)));
                         });

TEST(HyperelasticKernels, SimpleShearMatchesClosedForm) {
  for (const MaterialSpec& material : {neo_hookean(3000, 0.499), ogden_two_term()}) {
    const Scene s = hyper_block(8, material);
    const test::Model m = test::make_model(s);
    const HyperelasticLaw law = law_of(s.materials.at("soft"));
    const double gamma = 0.3;
    const auto f = device_forces(s, m, field(m.lattice, [&](const Vec3& X) { return Vec3(gamma * X.z(), 0, 0); }));
    double shear = 0;  // section force of the upper half, as in the uniaxial test
    for (std::size_t e = 0; e < m.lattice.element_count(); ++e)
      if (m.lattice.voxel_ijk(e)[2] >= 4) shear -= f[3 * e];
    const double sigma = shear / (7 * 7 * 0.002 * 0.002);  // the body's area, as above
    EXPECT_NEAR(sigma / simple_shear_stress(law, gamma), 1.0, 0.03) << material.law;
  }
}

TEST(HyperelasticKernels, CheckerboardDecaysWithHourglassControlAndPersistsWithout) {
  auto amplitude_after = [](double hourglass) {
    Scene s = hyper_block(8, neo_hookean(3000, 0.45));
    s.solver.hourglass = hourglass;
    s.solver.dashpot_ratio = 0.2;
    s.solver.damping_per_s = 0.1;
    s.solver.dt_s.reset();  // automatic
    const test::Model m = test::make_model(s);
    const auto checker = field(m.lattice, [&](const Vec3& X) {
      const Vec3 q = X / 0.002;
      const int parity = (int(std::floor(q.x())) + int(std::floor(q.y())) + int(std::floor(q.z()))) & 1;
      return Vec3(parity ? 1e-5 : -1e-5, 0, 0);
    });
    Simulator sim(s, m.lattice, m.elements, test::cl_context());
    sim.upload(checker, std::vector<double>(checker.size(), 0.0));
    sim.advance(2000);
    std::vector<double> u, v;
    sim.download(u, v);
    return max_abs(u) / max_abs(checker);
  };
  EXPECT_LT(amplitude_after(0.1), 0.1) << "with hourglass control the checkerboard must decay";
  EXPECT_GT(amplitude_after(0.0), 0.5) << "without it the checkerboard is a zero-energy mode";
}

/// A sagging two-term Ogden block of 7³ elements (double, dashpots, Heun) whose `held` lowest
/// layers are held; with the volume constraint when `volume` (its predicted stage under the lagged
/// pressure, the default).
Scene sagging_ogden_block(bool volume, int held = 1) {
  Scene s = hyper_block(7, ogden_two_term());
  s.solver.integrator = Integrator::Heun;
  s.solver.dashpot_ratio = 0.1;
  s.solver.dt_s.reset();
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -9.81);
  s.anchors.push_back(test::halfspace_anchor("base", Vec3(0, 0, 0.002 * held - 0.001), Vec3(0, 0, -1)));
  s.volume.preserve = volume;
  return s;
}

/// u then v after 100 Heun steps of `s` from a smooth deformation, with the environment variable
/// `env` set to `value` while the simulator is made; `check` sees the simulator then.
std::vector<double> heun_steps_with(const Scene& s, const char* env, const std::string& value,
                                    const std::function<void(const Simulator&)>& check) {
  const test::Model m = test::make_model(s);
  const auto u0 = field(m.lattice, [](const Vec3& X) {
    return Vec3(0.0002 * std::sin(300 * X.z()), 0.0001 * std::cos(400 * X.x()), -0.0002 * std::sin(250 * X.y()));
  });
  std::unique_ptr<Simulator> made;
  {
    const test::ScopedEnv set(env, value);
    made = std::make_unique<Simulator>(s, m.lattice, m.elements, test::cl_context());
  }
  Simulator& sim = *made;
  check(sim);
  sim.upload(u0, std::vector<double>(u0.size(), 0.0));
  sim.advance(100);
  std::vector<double> u, v;
  sim.download(u, v);
  u.insert(u.end(), v.begin(), v.end());
  return u;
}

std::vector<double> split_steps(int split) {
  return heun_steps_with(sagging_ogden_block(false), "VOXBREAST_FORCE_SPLIT", std::to_string(split),
                         [&](const Simulator& sim) { EXPECT_EQ(sim.force_split(), split); });
}

// Each element's connections summed by 2 or 4 work-items that meet in local memory (343 elements:
// the last work-group is partly empty): the same trajectory as one work-item per element up to the
// order of the sums. A part left out, counted twice or read before it is written would not be.
TEST(HyperelasticKernels, SplitForcePassesMatchOneWorkItemPerElement) {
  const std::vector<double> one = split_steps(1);
  for (const int split : {2, 4})
    EXPECT_LE(test::relative_difference(split_steps(split), one), 1e-12) << split << " work-items per element";
}

// Heun's two element stresses in one launch, the predicted stage's read as u + dt·v (kernels/
// hyperelastic.cl, VB_STRESS_PAIR), against two launches, the second reading the ũ heun_predict
// stored: the same trajectory (held base elements included, which the predicted stage does not
// move), with and without the volume constraint. A stress of the wrong stage (the pair's rows
// swapped, or the corrector reading the current stage's Q and C) would be a different Heun step.
// Three held layers: the lowest two are read by no free element, so the launch leaves them out
// (5 of 7 layers); an element left out that a free one reads would keep a stale stress.
TEST(HyperelasticKernels, PairedStressesMatchTwoLaunches) {
  for (const bool volume : {false, true}) {
    const Scene s = sagging_ogden_block(volume, 3);
    const auto two = heun_steps_with(s, "VOXBREAST_STRESS_PAIR", "0",
                                     [](const Simulator& sim) { EXPECT_FALSE(sim.stress_pair()); });
    const auto one = heun_steps_with(s, "VOXBREAST_STRESS_PAIR", "1", [](const Simulator& sim) {
      EXPECT_TRUE(sim.stress_pair());
      EXPECT_EQ(sim.stress_pass_elements(), 5u * 7 * 7);
    });
    const double diff = test::relative_difference(one, two);
    std::printf("volume %d: paired against two launches, max difference %.3g of the largest |u|, |v|\n", volume,
                diff);
    EXPECT_LE(diff, 1e-12) << (volume ? "with" : "without") << " the volume constraint";
  }
}

// Where something besides (u, v) moves the predicted stage, its stress is computed from the stored
// ũ as before: an indenter projects ũ out of itself, and the volume constraint's own projection of
// the predicted stage (predictor = "projection") moves its surface.
TEST(HyperelasticKernels, PairedStressesOnlyWhereThePredictedStageIsUPlusDtV) {
  Scene plain = sagging_ogden_block(false);
  const test::Model m = test::make_model(plain);
  EXPECT_TRUE(Simulator(plain, m.lattice, m.elements, test::cl_context()).stress_pair());
  Scene projected = sagging_ogden_block(true);
  projected.volume.predictor = VolumeSpec::Predictor::Projection;
  EXPECT_FALSE(Simulator(projected, m.lattice, m.elements, test::cl_context()).stress_pair());
  Scene indented = plain;
  IndenterSpec sphere;
  sphere.radius_m = 0.003;
  sphere.start_m = Vec3(0.007, 0.007, 0.02);
  sphere.velocity_m_s = Vec3(0, 0, -0.01);
  indented.indenters.push_back(sphere);
  EXPECT_FALSE(Simulator(indented, m.lattice, m.elements, test::cl_context()).stress_pair());
  Scene euler = plain;
  euler.solver.integrator = Integrator::SymplecticEuler;
  EXPECT_FALSE(Simulator(euler, m.lattice, m.elements, test::cl_context()).stress_pair());
}

}  // namespace
}  // namespace vb
