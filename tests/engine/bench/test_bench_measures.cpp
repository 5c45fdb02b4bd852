// The bench's error measures and design, without a device: field sampling across resolutions
// (exact for linear fields inside, constant fields everywhere, rotated lattices), the error
// norms, the laws' small-strain modulus, the column's free body at every downsample, and the
// design's size.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <set>

#include "engine/bench/bench_design.hpp"
#include "engine/bench/bench_knobs.hpp"
#include "engine/bench/bench_scenes.hpp"
#include "engine/bench/field_error.hpp"
#include "engine/error.hpp"
#include "engine/material/hyperelastic.hpp"
#include "engine/sim/element_setup.hpp"

namespace vb::bench {
namespace {

using Eigen::Vector3d;

/// A full nx × ny × nz label volume (one tissue) with the given placement.
LabelVolume block_volume(int nx, int ny, int nz, double h, const Eigen::Matrix3d& rotation, const Vector3d& origin) {
  LabelVolume v;
  v.dims = {nx, ny, nz};
  v.spacing_m = h;
  v.rotation = rotation;
  v.origin_m = origin;
  v.tissue_names = {"soft"};
  v.labels.assign(std::size_t(nx) * ny * nz, 1);
  return v;
}

std::vector<double> field_on(const Lattice& lat, const std::function<Vector3d(const Vector3d&)>& f) {
  std::vector<double> u(3 * lat.element_count());
  for (std::size_t e = 0; e < lat.element_count(); ++e) {
    const Vector3d v = f(lat.rest_position(e));
    for (int k = 0; k < 3; ++k) u[3 * e + k] = v[k];
  }
  return u;
}

std::vector<Vector3d> positions(const Lattice& lat) {
  std::vector<Vector3d> p;
  for (std::size_t e = 0; e < lat.element_count(); ++e) p.push_back(lat.rest_position(e));
  return p;
}

/// Is p inside the box spanned by the lattice's element centres (in its own frame)?
bool inside_centres(const Lattice& lat, const Vector3d& p) {
  const Vector3d q = lat.rotation.transpose() * (p - lat.origin_m) / lat.spacing_m;
  for (int a = 0; a < 3; ++a)
    if (q[a] < -1e-9 || q[a] > lat.dims[a] - 1 + 1e-9) return false;
  return true;
}

class FieldSampling : public ::testing::TestWithParam<int> {};

TEST_P(FieldSampling, CoarseFieldAtFinePointsIsExactForLinearInsideAndConstantEverywhere) {
  const int d = GetParam();
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.4, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const LabelVolume fine_volume = block_volume(8, 12, 16, 0.002, rotation, Vector3d(0.01, -0.02, 0.03));
  const Lattice fine = build_lattice(fine_volume), coarse = build_lattice(fine_volume, d);
  ASSERT_EQ(coarse.element_count(), fine.element_count() / (d * d * d));
  const Eigen::Matrix3d A = (Eigen::Matrix3d() << 0.01, -0.02, 0.03, 0.005, 0.0, -0.01, 0.02, 0.01, 0.004).finished();
  const Vector3d b(1e-3, -2e-3, 5e-4);
  const auto linear = [&](const Vector3d& x) -> Vector3d { return A * x + b; };
  const auto sampled_linear = sample_displacement(coarse, field_on(coarse, linear), positions(fine));
  const auto sampled_constant = sample_displacement(coarse, field_on(coarse, [&](const Vector3d&) { return b; }), positions(fine));
  int inside = 0;
  for (std::size_t e = 0; e < fine.element_count(); ++e) {
    const Vector3d x = fine.rest_position(e);
    EXPECT_LT((sampled_constant[e] - b).norm(), 1e-15) << "element " << e;
    if (!inside_centres(coarse, x)) continue;
    ++inside;
    EXPECT_LT((sampled_linear[e] - linear(x)).norm(), 1e-15) << "element " << e << " at downsample " << d;
  }
  // downsample 2: the fine centres strictly between the coarse ones; 4: fewer
  const int lost = 2 * (d / 2);  // fine centres beyond the outermost coarse ones, per axis
  EXPECT_EQ(inside, (8 - lost) * (12 - lost) * (16 - lost)) << "downsample " << d;
}

INSTANTIATE_TEST_SUITE_P(Downsample, FieldSampling, ::testing::Values(1, 2, 4));

TEST(FieldSampling, OwnPointsGiveTheFieldItself) {
  const Lattice lat = build_lattice(block_volume(5, 6, 7, 0.003, Eigen::Matrix3d::Identity(), Vector3d(0.1, 0.2, 0.3)));
  std::vector<double> u(3 * lat.element_count());
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = std::sin(1.7 * double(i));  // not smooth: any blending shows
  const auto sampled = sample_displacement(lat, u, positions(lat));
  for (std::size_t e = 0; e < lat.element_count(); ++e)
    EXPECT_EQ(sampled[e], Vector3d(u[3 * e], u[3 * e + 1], u[3 * e + 2])) << "element " << e;
}

TEST(FieldSampling, EmptyCornersAreLeftOutAndAPointFarFromAnyElementTakesTheNearest) {
  // Two 2-voxel-thick slabs along x with a 6-voxel gap: z displacement 1 on the left, 3 on the right.
  LabelVolume v = block_volume(10, 4, 4, 0.001, Eigen::Matrix3d::Identity(), Vector3d::Zero());
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 2; i < 8; ++i) v.labels[v.linear_index(i, j, k)] = 0;
  const Lattice lat = build_lattice(v);
  const auto u = field_on(lat, [](const Vector3d& x) { return Vector3d(0, 0, x.x() < 0.005 ? 1.0 : 3.0); });
  const auto s = sample_displacement(lat, u, {Vector3d(0.0015, 0.0015, 0.0015),   // cell (1..2): left corners only
                                              Vector3d(0.0030, 0.0015, 0.0015),   // no corner: nearest is left (x = 1 mm)
                                              Vector3d(0.0065, 0.0015, 0.0015),   // no corner: nearest is right (x = 8 mm)
                                              Vector3d(0.0500, -0.02, 0.0015)});  // outside: clamped onto x = 9 mm
  EXPECT_EQ(s[0], Vector3d(0, 0, 1));
  EXPECT_EQ(s[1], Vector3d(0, 0, 1));
  EXPECT_EQ(s[2], Vector3d(0, 0, 3));
  EXPECT_EQ(s[3], Vector3d(0, 0, 3));
}

TEST(FieldError, MaxAndRootMeanSquareOfTheDifferenceLengths) {
  const std::vector<Vector3d> ref(4, Vector3d(1, 2, 3));
  std::vector<Vector3d> u = ref;
  u[1] += Vector3d(3, 4, 0);  // |d| = 5
  u[3] += Vector3d(0, 0, -1);  // |d| = 1
  const FieldError e = field_error(u, ref);
  EXPECT_DOUBLE_EQ(e.max_m, 5);
  EXPECT_DOUBLE_EQ(e.rms_m, std::sqrt((25.0 + 1.0) / 4));
}

TEST(BenchKnobs, EveryLawKeepsTheTissuesSmallStrainModulus) {
  for (const std::string& law : law_names()) {
    Scene s = column_scene(4, 4, 0.005).scene;
    s.materials["bone"] = MaterialSpec{};
    s.materials["bone"].rigid = true;
    apply_law(s, law);
    const MaterialSpec& m = s.materials.at("soft");
    EXPECT_EQ(m.law, law);
    EXPECT_TRUE(s.materials.at("bone").law == "linear") << "rigid tissue keeps its law";
    if (law == "neo-hookean" || law == "ogden")
      EXPECT_NEAR(law_of(m).youngs_modulus_pa(), 20000, 1e-9) << law;
  }
  Scene s;
  EXPECT_THROW(apply_law(s, "hookean"), Error);
}

TEST(BenchKnobs, IntegratorNamesSetTheSolver) {
  Scene s;
  for (const std::string& name : integrator_names()) apply_integrator(s, name);
  apply_integrator(s, "symplectic_euler");
  EXPECT_EQ(s.solver.integrator, Integrator::SymplecticEuler);
  apply_integrator(s, "heun");
  EXPECT_EQ(s.solver.integrator, Integrator::Heun);
  EXPECT_THROW(apply_integrator(s, "rk4"), Error);
}

TEST(BenchScenes, ColumnKeepsTheSameFreeBodyAtEveryDownsample) {
  const BenchScene b = column_scene(8, 20, 0.0025);
  for (int d : {1, 2, 4}) {
    const Lattice lat = build_lattice(b.volume, d);
    const ElementArrays el = make_element_arrays(b.scene, lat);
    EXPECT_EQ(lat.element_count() - el.held_count, std::size_t(8 * 8 * 20 / (d * d * d))) << "downsample " << d;
    EXPECT_EQ(el.held_count, std::size_t(8 * 8 * 4 / (d * d * d))) << "downsample " << d;
  }
  EXPECT_NEAR(b.column->sag_m(), 1000 * 9.80665 * 0.05 * 0.05 / (2 * 20000), 1e-15);
}

TEST(BenchDesign, GridPlusOneFactorAtATimeEachCombinationOnce) {
  DesignSpec spec;
  spec.laws = law_names();
  spec.integrators = integrator_names();
  spec.precisions = {Precision::Float, Precision::Double};
  spec.base_laws = {"linear", "neo-hookean"};
  spec.downsamples = {1, 2, 4};
  spec.dt_factors = {0.5, 1, 2};
  spec.tolerances = {1e-9};
  const auto cases = make_design("column", spec);
  // grid: laws × integrators × 2 precisions; per base law: downsample 2, 4; dt 0.5, 2; volume;
  // tolerance × 2 precisions
  const std::size_t grid = law_names().size() * integrator_names().size() * 2;
  EXPECT_EQ(law_names().size(), 4u);
  EXPECT_EQ(cases.size(), grid + 2 * 7);
  std::set<std::string> knobs;
  for (const BenchCase& c : cases) EXPECT_TRUE(knobs.insert(c.knobs()).second) << "twice: " << c.knobs();
  EXPECT_EQ(cases.front().part, "base");
  const BenchCase r = reference_case(cases.back(), 0.5, 1e-11);
  EXPECT_EQ(r.precision, Precision::Double);
  EXPECT_EQ(r.downsample, 1);
  EXPECT_EQ(r.reference_key(), cases.back().reference_key());
}

}  // namespace
}  // namespace vb::bench
