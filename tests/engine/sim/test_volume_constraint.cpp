// Volume preservation ([volume] preserve, kernels/volume.cl; docs/PHYSICS.md "Volume
// preservation"): the device's enclosed volume and gradient against engine/surface's, a soft block
// squashed by its weight with and without the constraint (and with Heun's predicted stage under
// the lagged pressure against its projection), no action on rigid motion, and the bundled phantom
// lying prone.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>

#include "engine/image/image_lattice.hpp"
#include "engine/sim/run.hpp"
#include "engine/surface/enclosed_volume.hpp"
#include "io/nifti_io.hpp"
#include "io/scene_file.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"
#include "tests/engine/sim/trajectory_compare.hpp"

namespace vb {
namespace {

test::Model model_with_rotation(const Scene& s, const Eigen::Matrix3d& R) {
  LabelVolume vol = voxelise_shapes(s);
  vol.rotation = R;
  test::Model m;
  m.lattice = build_lattice(vol);
  m.elements = make_element_arrays(s, m.lattice);
  return m;
}

struct KernelCase {
  Precision precision;
  bool mirrored;  ///< det(rotation) = −1: the lattice-frame volume is negative
};

class VolumeKernels : public ::testing::TestWithParam<KernelCase> {};

TEST_P(VolumeKernels, VolumeAndGradientMatchHostOnDeformedBlock) {
  const KernelCase& p = GetParam();
  Scene s = test::box_scene(6, 5, 7, 0.004);
  s.solver.dashpot_ratio = 0.1;
  s.solver.precision = p.precision;
  s.volume.preserve = true;
  Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  if (p.mirrored) R = R * Eigen::Vector3d(1, -1, 1).asDiagonal();
  const test::Model m = model_with_rotation(s, R);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  // A smooth, non-affine deformation of up to a third of a spacing.
  const std::size_t n = m.lattice.element_count();
  std::vector<double> u(3 * n);
  for (std::size_t e = 0; e < n; ++e) {
    const Vec3 x = m.lattice.rest_position(e) / 0.004;
    u[3 * e] = 0.0013 * std::sin(0.7 * x.y() + 0.3 * x.z());
    u[3 * e + 1] = 0.0011 * std::cos(0.5 * x.x() - 0.4 * x.z());
    u[3 * e + 2] = 0.0009 * std::sin(0.6 * x.x() + 0.8 * x.y());
  }
  sim.upload(u, std::vector<double>(3 * n, 0.0));
  const SurfaceMesh mesh = build_surface(m.lattice);
  const std::vector<double> x = element_positions_m(m.lattice, u);
  const double v_host = enclosed_volume_m3(mesh, x), v_device = sim.enclosed_volume_m3();
  const std::vector<double> g_host = volume_gradient_m2(mesh, x), g_device = sim.volume_gradient_m2();
  const double tol = p.precision == Precision::Double ? 1e-12 : 2e-6;
  EXPECT_GT(v_host, 0);
  EXPECT_NEAR(v_device / v_host, 1.0, tol) << "host " << v_host << " device " << v_device;
  EXPECT_NEAR(sim.rest_volume_m3(), enclosed_volume_m3(mesh, element_positions_m(m.lattice)), 1e-15);
  double g_max = 0, err = 0;
  Vec3 sum = Vec3::Zero();
  for (std::size_t i = 0; i < g_host.size(); ++i) {
    g_max = std::max(g_max, std::abs(g_host[i]));
    err = std::max(err, std::abs(g_host[i] - g_device[i]));
    sum[int(i % 3)] += g_device[i];
  }
  EXPECT_LT(err, 10 * tol * g_max) << "largest gradient " << g_max;
  EXPECT_LT(sum.norm(), 10 * tol * g_max * std::sqrt(double(n)));  // Σ g = 0: no net force
  // the device sums V from the gradients (Σ x·g = 3V), the host over the triangles
  std::cout << (p.precision == Precision::Double ? "double" : "float") << (p.mirrored ? ", mirrored" : "")
            << ": V device/host - 1 = " << v_device / v_host - 1 << ", gradient error " << err / g_max
            << " of the largest\n";
}

INSTANTIATE_TEST_SUITE_P(Precisions, VolumeKernels,
                         ::testing::Values(KernelCase{Precision::Float, false}, KernelCase{Precision::Float, true},
                                           KernelCase{Precision::Double, false},
                                           KernelCase{Precision::Double, true}),
                         [](const auto& info) {
                           return std::string(info.param.precision == Precision::Double ? "Double" : "Float") +
                                  (info.param.mirrored ? "Mirrored" : "");
                         });

/// A soft 5 cm cube (linear springs, ν = 1/4) on a held base, squashed by its weight. With `sim_out`
/// the simulator is kept there (the constraint's scalars after the run).
RunOutput squash_block(bool preserve, Precision precision = Precision::Float, double tolerance = 1e-5,
                       VolumeSpec::Predictor predictor = VolumeSpec::Predictor::Pressure,
                       std::unique_ptr<Simulator>* sim_out = nullptr, const PlanOverrides& plan = {}) {
  const double h = 0.005;
  Scene s = test::box_scene(10, 10, 11, h, 3000);  // ρgL/E ≈ 16% strain at the base
  s.model.shapes[0].min_m.z() = -h;                 // the layer below z = 0 is held
  s.model.shapes[0].max_m.z() = 10 * h;
  s.anchors.push_back(test::halfspace_anchor("base", Vec3::Zero(), Vec3(0, 0, -1)));
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -9.81);
  s.solver.damping_per_s = 100;  // about critical for the first axial mode (≈ 54/s)
  s.solver.dashpot_ratio = 0.1;
  s.stop.equilibrium = tolerance;
  s.stop.max_steps = 20000;
  s.solver.precision = precision;
  s.volume.preserve = preserve;
  s.volume.predictor = predictor;
  const test::Model m = test::make_model(s);
  auto sim = std::make_unique<Simulator>(s, m.lattice, m.elements, test::cl_context(), plan);
  RunOutput out = run_simulation(s, m.lattice, m.elements, *sim);
  if (sim_out) *sim_out = std::move(sim);
  return out;
}

TEST(VolumeConstraint, HoldsTheVolumeOfASquashedBlock) {
  const RunOutput free_run = squash_block(false), held_run = squash_block(true);
  const double free_change = free_run.summary.surface_volume_change;
  const double held_change = held_run.summary.surface_volume_change;
  std::cout << "block: surface dV/V without " << free_change << " (" << free_run.summary.steps << " steps), with "
            << held_change << " (" << held_run.summary.steps << " steps); max |u| "
            << free_run.summary.max_displacement_m << " / " << held_run.summary.max_displacement_m << " m; residual "
            << held_run.summary.final_residual << ", speed ratio " << held_run.summary.final_speed_ratio << "\n";
  RecordProperty("dV_over_V_without", std::to_string(free_change));
  RecordProperty("dV_over_V_with", std::to_string(held_change));
  EXPECT_TRUE(free_run.summary.converged) << free_run.summary.stop_reason;
  EXPECT_TRUE(held_run.summary.converged) << held_run.summary.stop_reason;
  EXPECT_GT(std::abs(free_change), 0.01);
  EXPECT_LE(std::abs(held_change), 0.005);
  for (const double x : held_run.state.displacement_m) ASSERT_TRUE(std::isfinite(x));
  EXPECT_GT(held_run.summary.max_displacement_m, 0.3 * free_run.summary.max_displacement_m);  // it still sags
}

// Heun's predicted stage under the last corrections' pressure (the default) instead of its own
// projection: the same constrained equilibrium, and at it the lagged multiplier is the constraint's
// pressure, M/dt = p (kernels/volume.cl: the fixed point of M ← μ + M/2). Float steps with the
// lanes kernels on CPUs, double with the real4 ones. On NVIDIA GPUs with one launch per pass: the
// one-launch step of spring models (kernels/persistent.cl) projects the predicted stage.
TEST(VolumeConstraint, LaggedPressureReachesTheProjectedEquilibrium) {
  PlanOverrides launched;
  launched.persistent = false;
  for (const auto& [precision, tolerance] : {std::pair{Precision::Double, 1e-8}, std::pair{Precision::Float, 1e-5}}) {
    std::unique_ptr<Simulator> lagged, projected;
    const RunOutput a = squash_block(true, precision, tolerance, VolumeSpec::Predictor::Pressure, &lagged, launched);
    const RunOutput b =
        squash_block(true, precision, tolerance, VolumeSpec::Predictor::Projection, &projected, launched);
    const char* name = precision == Precision::Double ? "double" : "float";
    EXPECT_TRUE(lagged->volume_predictor_pressure());
    EXPECT_FALSE(projected->volume_predictor_pressure());
    ASSERT_TRUE(a.summary.converged) << name << ": " << a.summary.stop_reason;
    ASSERT_TRUE(b.summary.converged) << name << ": " << b.summary.stop_reason;
    double du = 0, u_max = 0;
    for (std::size_t i = 0; i < a.state.displacement_m.size(); ++i) {
      du = std::max(du, std::abs(a.state.displacement_m[i] - b.state.displacement_m[i]));
      u_max = std::max(u_max, std::abs(b.state.displacement_m[i]));
    }
    const Simulator::VolumeScalars s = lagged->volume_scalars();
    const double p_lagged = s.lagged / lagged->dt_s();
    std::cout << name << ": lagged pressure " << a.summary.steps << " steps, projected " << b.summary.steps
              << "; max |du| " << du << " m of max |u| " << u_max << " m; M/dt " << p_lagged << " Pa, p "
              << s.pressure_pa << " Pa; surface dV/V " << a.summary.surface_volume_change << " / "
              << b.summary.surface_volume_change << "\n";
    EXPECT_LE(du, 1e-4 * u_max) << name;
    EXPECT_LE(std::abs(a.summary.steps - b.summary.steps), b.summary.steps / 5) << name;
    EXPECT_LE(std::abs(a.summary.surface_volume_change), 1e-5) << name;
    EXPECT_GT(std::abs(s.pressure_pa), 0) << name;
    EXPECT_NEAR(p_lagged, s.pressure_pa, 1e-3 * std::abs(s.pressure_pa)) << name;
  }
}

/// One step of a rigidly rotated and shifted box moving rigidly (translation + rotation ω), with
/// and without the constraint: the largest change the constraint makes to u and to v, and the
/// net momentum it adds (Σ Δv, equal masses), relative to the largest Δv.
struct RigidStep {
  double du = 0, dv = 0, net_dv = 0, dt = 0, volume_ratio = 0;
};

RigidStep rigid_step(const Vec3& omega, const Vec3& velocity) {
  const double h = 0.004;
  Scene s = test::box_scene(6, 6, 6, h);
  s.solver.precision = Precision::Double;
  s.solver.dashpot_ratio = 0.1;
  const test::Model m = test::make_model(s);
  const std::size_t n = m.lattice.element_count();
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(0.5, Vec3(1, -1, 2).normalized()).toRotationMatrix();
  const Vec3 shift(0.003, -0.002, 0.001), c = m.lattice.rest_position(n / 2);
  std::vector<double> u(3 * n), v(3 * n);
  for (std::size_t e = 0; e < n; ++e) {
    const Vec3 X = m.lattice.rest_position(e), x = c + Q * (X - c) + shift;
    const Vec3 ue = x - X, ve = velocity + omega.cross(x - c - shift);
    for (int k = 0; k < 3; ++k) u[3 * e + k] = ue[k], v[3 * e + k] = ve[k];
  }
  std::vector<double> u_off, v_off, u_on, v_on;
  RigidStep r;
  for (const bool preserve : {false, true}) {
    s.volume.preserve = preserve;
    Simulator sim(s, m.lattice, m.elements, test::cl_context());
    sim.upload(u, v);
    if (preserve) r.volume_ratio = sim.enclosed_volume_m3() / sim.rest_volume_m3();
    sim.advance(1);
    r.dt = sim.dt_s();
    sim.download(preserve ? u_on : u_off, preserve ? v_on : v_off);
  }
  Vec3 net = Vec3::Zero();
  for (std::size_t i = 0; i < 3 * n; ++i) {
    r.du = std::max(r.du, std::abs(u_on[i] - u_off[i]));
    r.dv = std::max(r.dv, std::abs(v_on[i] - v_off[i]));
    net[int(i % 3)] += v_on[i] - v_off[i];
  }
  r.net_dv = net.norm();
  return r;
}

/// 150 Heun steps of the squashed block from rest, the projection as one launch (volume_project,
/// PlanOverrides::volume_launches = 1), two (2: volume_partials, volume_apply) or left pending for the
/// next kernels (0: volume_pending); with checks (which apply a pending projection) after steps 50
/// and 100; two-term Ogden instead of springs when `ogden`, projecting every `every` steps.
/// Returns u then v.
std::vector<double> project_steps(int launches, bool ogden = false, int every = 1,
                                  VolumeSpec::Predictor predictor = VolumeSpec::Predictor::Pressure) {
  Scene s = test::box_scene(10, 10, 11, 0.005, 3000);
  if (ogden) s.materials["soft"] = test::validation_material("ogden", 0.45);
  s.volume.every = every;
  s.volume.predictor = predictor;
  s.anchors.push_back(test::halfspace_anchor("base", Vec3(0, 0, 0.0025), Vec3(0, 0, -1)));
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -9.81);
  s.solver.precision = Precision::Double;
  s.solver.dashpot_ratio = 0.1;
  s.volume.preserve = true;
  const test::Model m = test::make_model(s);
  PlanOverrides o;
  o.volume_launches = launches;
  // the launches named here: on NVIDIA GPUs a spring model's Heun step is otherwise one persistent
  // launch, projections included, and every form would compare equal (test_persistent_step.cpp)
  o.persistent = false;
  Simulator sim(s, m.lattice, m.elements, test::cl_context(), o);
  EXPECT_EQ(sim.volume_launches(), launches);
  for (int k = 0; k < 3; ++k) {
    sim.advance(50);
    if (k < 2) EXPECT_EQ(sim.check().nonfinite_elements, 0);
  }
  std::vector<double> u, v;
  sim.download(u, v);
  u.insert(u.end(), v.begin(), v.end());
  return u;
}

// volume_project's last work-group sums every group's partials (~10 groups here): a group
// counted before its partials or gradients were visible, or a missed reset of the count, would
// give another λ, μ and another trajectory than the two-launch form. Both also update the lagged
// multiplier the predicted stage feels (the default predictor): a wrong one in either differs too.
TEST(VolumeConstraint, OneLaunchProjectionMatchesTwoLaunches) {
  EXPECT_LE(test::relative_difference(project_steps(1), project_steps(2)), 1e-12);
}

// Folded projections (volume_launches = 0): no volume_apply in the step; the stress pass and the stepping
// kernels read every projected state as u + λ·w·g, v − μ·w·g. A reader that missed the projection
// (the stress pass, a neighbour's or the element's own u or v, the state a check reads) or one that
// applied the wrong one (the state's instead of the predicted stage's) gives another trajectory.
// Two-term Ogden projecting every third step has steps with and without pending projections.
// Folded projections project the predicted stage, so the two-launch run is asked to as well.
TEST(VolumeConstraint, PendingProjectionMatchesTwoLaunches) {
  const double springs = test::relative_difference(project_steps(0),
                                                   project_steps(2, false, 1, VolumeSpec::Predictor::Projection));
  const double ogden = test::relative_difference(project_steps(0, true, 3), project_steps(2, true, 3));
  std::cout << "pending vs two launches, largest difference over largest |u|, |v|: springs " << springs
            << ", two-term Ogden (every third step) " << ogden << "\n";
  EXPECT_LE(springs, 1e-12);
  EXPECT_LE(ogden, 1e-12);
}

TEST(VolumeConstraint, DoesNothingToRigidMotion) {
  // A rigid state has V = V0, and a translation has Σ g·v = 0: nothing changes.
  const Vec3 velocity(0.02, 0.01, -0.03), omega(0.4, 0.1, -0.3);
  const RigidStep t = rigid_step(Vec3::Zero(), velocity);
  EXPECT_NEAR(t.volume_ratio, 1.0, 1e-13);
  EXPECT_LT(t.du, 1e-15) << "the correction moved a translating body";
  EXPECT_LT(t.dv, 1e-13 * velocity.norm()) << "the correction changed a translation";
  // A linear step along a rotation velocity gains volume at second order ((ω·dt)² relative), and
  // the linear velocity field at the moved positions has dV/dt ∝ dt·|ω|²: the constraint takes
  // exactly these back, with no net force.
  const RigidStep r = rigid_step(omega, velocity);
  const double L = 6 * 0.004, w = omega.norm();
  std::cout << "rigid rotation: dt " << r.dt << " s, max du " << r.du << " m, max dv " << r.dv << " m/s, |Σ dv| "
            << r.net_dv << "\n";
  EXPECT_LT(r.du, std::pow(w * r.dt, 2) * L);
  EXPECT_LT(r.dv, w * w * r.dt * L);
  EXPECT_LT(r.net_dv, 1e-9 * r.dv * 216) << "the correction exerts a net force";
}

/// The bundled phantom CT lying prone from its (supine) rest shape, exactly as
/// data-samples/phantom/scene.toml runs it (4 mm, 18,413 elements, Heun, float).
RunOutput phantom_prone(bool preserve, double& steps_per_s) {
  const std::string samples = std::string(VOXBREAST_SOURCE_DIR) + "/data-samples/";
  Scene scene = parse_scene_file(samples + "phantom/scene.toml");
  scene.volume.preserve = preserve;
  static const ImageVolume ct = read_nifti(scene.model.image_path);
  static const ImageVolume labels = read_nifti(scene.model.labels_path);
  const TissueMap map = classify_image(scene.model, ct, &labels);
  test::Model m;
  m.lattice = build_lattice(lattice_volume_from_image(scene.model, ct, map), scene.model.downsample);
  m.elements = make_element_arrays(scene, m.lattice);
  Simulator sim(scene, m.lattice, m.elements, test::cl_context());
  RunOutput out = run_simulation(scene, m.lattice, m.elements, sim);
  steps_per_s = out.summary.steps_per_second;
  std::cout << "phantom (" << m.lattice.element_count() << " elements, preserve " << preserve
            << "): surface dV/V " << out.summary.surface_volume_change << ", element dV/V "
            << out.summary.volume_change << ", " << out.summary.steps << " steps, " << steps_per_s
            << " steps/s, converged " << out.summary.converged << "\n";
  return out;
}

TEST(VolumeConstraint, PhantomProneKeepsItsVolume) {
  double rate_off = 0, rate_on = 0;
  const RunOutput off = phantom_prone(false, rate_off), on = phantom_prone(true, rate_on);
  RecordProperty("dV_over_V_without", std::to_string(off.summary.surface_volume_change));
  RecordProperty("dV_over_V_with", std::to_string(on.summary.surface_volume_change));
  EXPECT_TRUE(on.summary.converged) << on.summary.stop_reason;
  EXPECT_LE(std::abs(on.summary.surface_volume_change), 0.005);
  EXPECT_GT(std::abs(off.summary.surface_volume_change), std::abs(on.summary.surface_volume_change));
  for (const double x : on.state.displacement_m) ASSERT_TRUE(std::isfinite(x));
}

}  // namespace
}  // namespace vb
