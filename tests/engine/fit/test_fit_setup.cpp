// The host-side pieces of inverse fitting (docs/FIT.md): the [fit] table, the HU → E rule, the
// regions, and sampling an observation at element centres. The fits themselves are checked end
// to end by tests/apps/fit_cli.sh.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "engine/error.hpp"
#include "engine/fit/fit_regions.hpp"
#include "engine/fit/initial_guess.hpp"
#include "engine/fit/observation.hpp"
#include "engine/lattice/voxelise.hpp"
#include "engine/loads/posture.hpp"
#include "engine/sim/run.hpp"
#include "io/fit_file.hpp"
#include "io/fit_landmarks_csv.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

const std::string kObservation = "[gravity]\nposture = \"prone\"\n[fit]\ndvf = \"obs.nii.gz\"\n";

std::string error_of(const std::string& text) {
  try {
    (void)parse_fit_section(text, "/data/case/scene.toml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(FitFile, DefaultsAndResolvedPaths) {
  const FitSpec f = parse_fit_section(kObservation + "from_posture = \"supine\"\nmask = \"/abs/mask.nii\"\n",
                                      "/data/case/scene.toml");
  EXPECT_EQ(f.dvf_path, "/data/case/obs.nii.gz");
  EXPECT_EQ(f.mask_path, "/abs/mask.nii");
  ASSERT_TRUE(f.from_gravity_m_s2.has_value());
  EXPECT_TRUE(f.from_gravity_m_s2->isApprox(gravity_for_posture("supine")));
  EXPECT_EQ(f.regions, FitSpec::Regions::Labels);
  EXPECT_EQ(f.method, FitSpec::Method::GaussNewton);
  EXPECT_DOUBLE_EQ(f.sigma_m, 0.001);
  EXPECT_FALSE(parse_fit_section(kObservation + "from_posture = \"none\"\n", "s.toml").from_gravity_m_s2);
}

TEST(FitFile, StrictErrorsNameTheKey) {
  EXPECT_NE(error_of(kObservation + "regoins = \"blocks\"\n").find("fit.regoins"), std::string::npos);
  EXPECT_NE(error_of(kObservation + "regions = \"voxels\"\n").find("fit.regions"), std::string::npos);
  EXPECT_NE(error_of(kObservation + "block_mm = 10\n").find("only with regions"), std::string::npos);
  EXPECT_NE(error_of("[fit]\nmethod = \"bisection\"\n").find("needs an observation"), std::string::npos);
  EXPECT_NE(error_of(kObservation + "min_E = 5000\nmax_E = 1000\n").find("fit.max_E"), std::string::npos);
  EXPECT_NE(error_of("[gravity]\nposture = \"prone\"\n").find("no [fit] table"), std::string::npos);
  EXPECT_NE(error_of(kObservation + "from_posture = \"sideways\"\n").find("fit.from_posture"), std::string::npos);
}

// The [fit] table is read by the scene file's own typed access (io/toml_section.hpp), so its
// values meet the same rules as the rest of the scene: counts are integers, numbers finite.
TEST(FitFile, ImpossibleValuesAreRefusedWithTheirKey) {
  EXPECT_NE(error_of(kObservation + "max_iterations = 2.5\n").find("fit.max_iterations"), std::string::npos);
  EXPECT_NE(error_of(kObservation + "max_steps = 1e30\n").find("fit.max_steps"), std::string::npos);
  EXPECT_NE(error_of(kObservation + "max_steps = 0\n").find("fit.max_steps"), std::string::npos);
  EXPECT_NE(error_of(kObservation + "max_E = inf\n").find("fit.max_E"), std::string::npos);
  EXPECT_NE(error_of(kObservation + "tolerance = nan\n").find("fit.tolerance"), std::string::npos);
  EXPECT_NE(error_of(kObservation + "from_gravity = [0, nan, 0]\n").find("fit.from_gravity"), std::string::npos);
  EXPECT_NE(error_of(kObservation + "sigma_mm = -1\n").find("fit.sigma_mm"), std::string::npos);
  EXPECT_NE(error_of(kObservation + "method = \"gauss_newton\"\n").find("gauss-newton"), std::string::npos);  // the hint
  const FitSpec f = parse_fit_section(kObservation + "max_iterations = 7\nmax_steps = 90000\nmethod = \"bisection\"\n"
                                      "regions = \"blocks\"\nblock_mm = 12\ninitial = \"materials\"\n", "s.toml");
  EXPECT_EQ(f.max_iterations, 7);
  EXPECT_EQ(f.max_steps, 90000);
  EXPECT_EQ(f.method, FitSpec::Method::Bisection);
  EXPECT_EQ(f.regions, FitSpec::Regions::Blocks);
  EXPECT_DOUBLE_EQ(f.block_m, 0.012);
  EXPECT_EQ(f.initial, FitSpec::Initial::Materials);
}

TEST(FitFile, BatchIsAutoOrACount) {
  EXPECT_EQ(parse_fit_section(kObservation, "s.toml").batch, 0);  // auto
  EXPECT_EQ(parse_fit_section(kObservation + "batch = \"auto\"\n", "s.toml").batch, 0);
  EXPECT_EQ(parse_fit_section(kObservation + "batch = 1\n", "s.toml").batch, 1);
  EXPECT_EQ(parse_fit_section(kObservation + "batch = 12\n", "s.toml").batch, 12);
  EXPECT_NE(error_of(kObservation + "batch = -1\n").find("fit.batch"), std::string::npos);
  EXPECT_NE(error_of(kObservation + "batch = 2.5\n").find("fit.batch"), std::string::npos);
  EXPECT_NE(error_of(kObservation + "batch = \"all\"\n").find("fit.batch"), std::string::npos);
}

TEST(FitFile, LabelMapObservationAndUnloadedReference) {
  const std::string labels = "[gravity]\nposture = \"prone\"\n[fit]\nobserved_labels = \"prone_labels.nii.gz\"\n";
  const FitSpec f = parse_fit_section(labels + "observed_label_values = [0, 6]\nunloaded_reference = false\n",
                                      "/data/case/scene.toml");
  EXPECT_EQ(f.observed_labels_path, "/data/case/prone_labels.nii.gz");
  EXPECT_EQ(f.observed_label_values, (std::vector<int>{0, 6}));
  ASSERT_TRUE(f.unloaded_reference.has_value());
  EXPECT_FALSE(*f.unloaded_reference);
  EXPECT_FALSE(parse_fit_section(labels, "/s.toml").unloaded_reference.has_value());  // unset: follows the scene
  EXPECT_NE(error_of(labels + "dvf = \"obs.nii.gz\"\n").find("one kind of observation"), std::string::npos);
  EXPECT_NE(error_of(kObservation + "observed_label_values = [6]\n").find("only with 'observed_labels'"), std::string::npos);
  EXPECT_NE(error_of(labels + "observed_label_values = [-1]\n").find("fit.observed_label_values"), std::string::npos);
  EXPECT_NE(error_of(labels + "unloaded_reference = 1\n").find("true or false"), std::string::npos);
}

TEST(FitInitialGuess, HuRuleIsLogLinearAndClamped) {
  EXPECT_DOUBLE_EQ(modulus_from_hu(kFatHu, 3000, 12000), 3000);
  EXPECT_DOUBLE_EQ(modulus_from_hu(kGlandHu, 3000, 12000), 12000);
  EXPECT_NEAR(modulus_from_hu(0.5 * (kFatHu + kGlandHu), 3000, 12000), 6000, 1e-9);  // geometric mean
  EXPECT_DOUBLE_EQ(modulus_from_hu(-1000, 3000, 12000), 3000);
  EXPECT_DOUBLE_EQ(modulus_from_hu(500, 3000, 12000), 12000);
}

TEST(FitRegions, BlocksLabelsAndRigidTissue) {
  const double h = 0.002;
  Scene s = test::box_scene(6, 6, 4, h, 3000);
  ShapeSpec bone = s.model.shapes[0];
  bone.max_m.z() = h;  // the bottom layer
  bone.label = "bone";
  s.model.shapes.push_back(bone);
  s.materials["bone"] = test::material("bone", 1e9);
  s.materials["bone"].rigid = true;
  const Lattice lattice = build_lattice(voxelise_shapes(s));
  FitSpec f;
  f.regions = FitSpec::Regions::Blocks;
  f.block_m = 3 * h;
  const FitRegions blocks = make_fit_regions(f, s, lattice);
  ASSERT_EQ(blocks.size(), 2u * 2u * 1u + 2u * 2u * 1u);  // 3×3×3 blocks over the 6×6×3 soft part
  std::size_t fitted = 0;
  for (std::size_t n : blocks.element_count) fitted += n;
  EXPECT_EQ(fitted, 6u * 6u * 3u);  // every soft element, no bone
  f.regions = FitSpec::Regions::Labels;
  const FitRegions labels = make_fit_regions(f, s, lattice);
  ASSERT_EQ(labels.size(), 1u);
  EXPECT_EQ(labels.names[0], "soft");
  f.tissues = {"bone"};
  EXPECT_THROW(make_fit_regions(f, s, lattice), Error);
  f.tissues = {"fat"};
  EXPECT_THROW(make_fit_regions(f, s, lattice), Error);
  const auto [lo, hi] = modulus_bounds(FitSpec{}, s, lattice, labels);
  EXPECT_DOUBLE_EQ(lo, 750);
  EXPECT_DOUBLE_EQ(hi, 30000);
}

TEST(FitObservation, FieldOnTheLatticeGridIsExactAtElements) {
  const double h = 0.003;
  const Scene s = test::box_scene(4, 3, 5, h);
  const Lattice lattice = build_lattice(voxelise_shapes(s));
  ImageVolume grid;
  grid.dims = {lattice.dims[0] + 2, lattice.dims[1] + 2, lattice.dims[2] + 2};  // a margin around it
  grid.affine_lps_m = lattice.affine();
  grid.affine_lps_m.topRightCorner<3, 1>() -= h * Eigen::Vector3d(1, 1, 1);
  std::vector<float> field(3 * grid.voxel_count());
  for (int k = 0; k < grid.dims[2]; ++k)  // a linear field: trilinear sampling is exact anywhere
    for (int j = 0; j < grid.dims[1]; ++j)
      for (int i = 0; i < grid.dims[0]; ++i) {
        const Eigen::Vector3d p = grid.world_of_index(Eigen::Vector3d(i, j, k));
        const std::size_t v = grid.linear_index(i, j, k);
        field[3 * v] = float(0.1 * p.x() + 0.001);
        field[3 * v + 1] = float(-0.2 * p.z());
        field[3 * v + 2] = float(0.002);
      }
  const Observation obs = observation_from_field(lattice, grid, field, 0.0005);
  EXPECT_EQ(obs.observed_elements(), lattice.element_count());
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    const Eigen::Vector3d p = lattice.rest_position(e);
    EXPECT_NEAR(obs.displacement_m[3 * e], 0.1 * p.x() + 0.001, 1e-8);
    EXPECT_NEAR(obs.displacement_m[3 * e + 1], -0.2 * p.z(), 1e-8);
    EXPECT_DOUBLE_EQ(obs.weight_per_m2[e], 1 / (0.0005 * 0.0005));
  }
  // Residual statistics: one element 2 mm off, the rest exact.
  std::vector<double> sim = obs.displacement_m;
  sim[0] += 0.002;
  const ResidualStats stats = residual_stats(obs, sim);
  EXPECT_NEAR(stats.max_m, 0.002, 1e-12);
  EXPECT_NEAR(stats.within_1mm, 1 - 1.0 / double(lattice.element_count()), 1e-12);
}

TEST(FitObservation, LandmarksObserveTheirElements) {
  const double h = 0.003;
  const Scene s = test::box_scene(4, 4, 4, h);
  const Lattice lattice = build_lattice(voxelise_shapes(s));
  const std::string path = (std::filesystem::temp_directory_path() / "vb_fit_landmarks.csv").string();
  std::ofstream(path) << "x_mm,y_mm,z_mm,dx_mm,dy_mm,dz_mm,sigma_mm\n"
                      << "1.5,1.5,1.5,0.1,0.2,0.3,0.5\n4.5,7.5,10.5,1,0,-1,0\n";
  const std::vector<Landmark> marks = read_fit_landmarks(path);
  ASSERT_EQ(marks.size(), 2u);
  const Observation obs = observation_from_landmarks(lattice, marks, 0.001);
  EXPECT_EQ(obs.observed_elements(), 2u);
  const std::size_t first = nearest_element(lattice, Vec3(0.0015, 0.0015, 0.0015));
  EXPECT_NEAR(obs.displacement_m[3 * first + 2], 0.0003, 1e-12);
  EXPECT_DOUBLE_EQ(obs.weight_per_m2[first], 1 / (0.0005 * 0.0005));
  const std::size_t second = nearest_element(lattice, Vec3(0.0045, 0.0075, 0.0105));
  EXPECT_DOUBLE_EQ(obs.weight_per_m2[second], 1 / (0.001 * 0.001));  // the fit's sigma
  EXPECT_THROW(observation_from_landmarks(lattice, {marks[0], marks[0]}, 0.001), Error);  // one element
  Landmark outside;
  outside.point_m = Vec3(0.5, 0, 0);
  EXPECT_THROW(observation_from_landmarks(lattice, {outside}, 0.001), Error);
  std::ofstream(path) << "x,y,z\n1,2,3\n";
  EXPECT_THROW(read_fit_landmarks(path), Error);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace vb
