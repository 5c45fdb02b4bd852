#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/error.hpp"
#include "engine/loads/posture.hpp"
#include "io/scene_file.hpp"

namespace vb {
namespace {

constexpr double g = kStandardGravity_m_s2;

// A minimal valid scene; the error cases below count lines from it.
const std::string kBase =
    "[model]\n"                   // 1
    "spacing = 0.002\n"           // 2
    "[[model.shape]]\n"           // 3
    "kind = \"box\"\n"            // 4
    "min = [0, 0, 0]\n"           // 5
    "max = [0.02, 0.02, 0.02]\n"  // 6
    "label = \"adipose\"\n"       // 7
    "[materials.adipose]\n"       // 8
    "E = 3000.0\n";               // 9

/// kBase (or `text`) with the first `from` replaced by `to`.
std::string with(const std::string& from, const std::string& to, std::string text = kBase) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("test text lacks '" + from + "'");
  return text.replace(at, from.size(), to);
}

/// 1-based line of the n-th (0-based) occurrence of `needle`.
int line_of(const std::string& text, const std::string& needle, int n = 0) {
  std::size_t at = text.find(needle);
  for (int i = 0; i < n && at != std::string::npos; ++i) at = text.find(needle, at + 1);
  if (at == std::string::npos) throw std::logic_error("test text lacks '" + needle + "'");
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

void expect_vec(const Vec3& v, double x, double y, double z) {
  EXPECT_NEAR(v.x(), x, 1e-12);
  EXPECT_NEAR(v.y(), y, 1e-12);
  EXPECT_NEAR(v.z(), z, 1e-12);
}

const std::string kFullScene = R"(# every section, every key
[model]
spacing = 0.001
downsample = 2

[[model.shape]]
kind = "box"
min = [-0.05, -0.05, 0]
max = [0.05, 0.05, 0.01]
label = "skin"

[[model.shape]]
kind = "half_ellipsoid"
center = [0, 0, 0.01]
radii = [0.05, 0.04, 0.06]
axis = [0, 0, 2]
label = "adipose"

[[model.shape]]
kind = "sphere"
center = [0, 0, 0.03]
radius = 0.01
label = "tumour"

[[model.shape]]
kind = "ellipsoid"
center = [0, 0, 0.02]
radii = [0.02, 0.02, 0.01]
label = "glandular"

[[model.shape]]
kind = "hemisphere"
center = [0, 0, 0]
radius = 0.02
label = "glandular"

[materials.adipose]
law = "linear"
E = 3000
density = 950.0

[materials.glandular]
E = 9.5e3

[materials.skin]
E = 60000.0
density = 1100

[materials.tumour]
E = 2.5e4

[solver]
integrator = "euler"
dt = 1e-5
dt_safety = 0.8
precision = "double"
damping = 5
dashpot_ratio = 0.2
check_every = 50

[gravity]
posture = "prone"
magnitude = 4.903325

[anchor.chest]
kind = "sphere"
center = [0, 0.1, 0]
radius = 0.1
rpy_deg = [0, 10, 0]

[anchor.base]
kind = "halfspace"
point = [0, 0, 0]
normal = [0, 0, -3]

[anchor.block]
kind = "box"
min = [-0.06, -0.06, -0.01]
max = [0.06, 0.06, 0.0]

[[indenter]]
kind = "sphere"
radius = 0.005
start = [0, 0, 0.08]
velocity = [0, 0, -0.001]
travel_time = 10

[[indenter]]
kind = "plate"
start = [0, 0, -0.001]
normal = [0, 0, 1]
contact = "slide"

[[track]]
name = "apex"
point = [0, 0, 0.07]

[[track]]
name = "lateral"
point = [0.04, 0, 0.02]

[stop]
equilibrium = 1e-5
max_steps = 5000000000
time = 2.5

[output]
frames_every = 100
)";

TEST(SceneFile, FullSceneParsesToExpectedValues) {
  const Scene s = parse_scene_text(kFullScene, "full.toml");
  EXPECT_EQ(s.source_text, kFullScene);
  EXPECT_DOUBLE_EQ(s.model.spacing_m, 0.001);
  EXPECT_EQ(s.model.downsample, 2);

  ASSERT_EQ(s.model.shapes.size(), 5u);
  const ShapeSpec& box = s.model.shapes[0];
  EXPECT_EQ(box.kind, ShapeSpec::Kind::Box);
  expect_vec(box.min_m, -0.05, -0.05, 0);
  expect_vec(box.max_m, 0.05, 0.05, 0.01);
  EXPECT_EQ(box.label, "skin");
  EXPECT_EQ(box.line, line_of(kFullScene, "[[model.shape]]", 0));
  const ShapeSpec& half = s.model.shapes[1];
  EXPECT_EQ(half.kind, ShapeSpec::Kind::HalfEllipsoid);
  expect_vec(half.radii_m, 0.05, 0.04, 0.06);
  expect_vec(half.axis, 0, 0, 1);  // normalised
  EXPECT_EQ(half.line, line_of(kFullScene, "[[model.shape]]", 1));
  EXPECT_EQ(s.model.shapes[2].kind, ShapeSpec::Kind::Sphere);
  EXPECT_DOUBLE_EQ(s.model.shapes[2].radius_m, 0.01);
  EXPECT_EQ(s.model.shapes[3].kind, ShapeSpec::Kind::Ellipsoid);
  expect_vec(s.model.shapes[3].center_m, 0, 0, 0.02);
  EXPECT_EQ(s.model.shapes[4].kind, ShapeSpec::Kind::Hemisphere);
  expect_vec(s.model.shapes[4].axis, 0, 0, 1);  // default

  ASSERT_EQ(s.materials.size(), 4u);
  const MaterialSpec& adipose = s.materials.at("adipose");
  EXPECT_EQ(adipose.name, "adipose");
  EXPECT_EQ(adipose.law, "linear");
  EXPECT_DOUBLE_EQ(adipose.youngs_modulus_pa, 3000);  // integer accepted
  EXPECT_DOUBLE_EQ(adipose.density_kg_m3, 950);
  EXPECT_EQ(adipose.line, line_of(kFullScene, "[materials.adipose]"));
  EXPECT_DOUBLE_EQ(s.materials.at("glandular").density_kg_m3, 1000);  // default
  EXPECT_DOUBLE_EQ(s.materials.at("skin").youngs_modulus_pa, 60000);

  EXPECT_EQ(s.solver.integrator, Integrator::SymplecticEuler);
  ASSERT_TRUE(s.solver.dt_s.has_value());
  EXPECT_DOUBLE_EQ(*s.solver.dt_s, 1e-5);
  EXPECT_DOUBLE_EQ(s.solver.dt_safety, 0.8);
  EXPECT_EQ(s.solver.precision, Precision::Double);
  EXPECT_DOUBLE_EQ(s.solver.damping_per_s, 5);
  EXPECT_DOUBLE_EQ(s.solver.dashpot_ratio, 0.2);
  EXPECT_EQ(s.solver.check_every, 50);

  EXPECT_TRUE(s.gravity.active);
  EXPECT_EQ(s.gravity.posture, "prone");
  expect_vec(s.gravity.acceleration_m_s2, 0, -4.903325, 0);

  ASSERT_EQ(s.anchors.size(), 3u);  // file order
  EXPECT_EQ(s.anchors[0].name, "chest");
  EXPECT_EQ(s.anchors[0].kind, AnchorSpec::Kind::Sphere);
  EXPECT_DOUBLE_EQ(s.anchors[0].radius_m, 0.1);
  expect_vec(s.anchors[0].rpy_deg, 0, 10, 0);
  EXPECT_EQ(s.anchors[0].line, line_of(kFullScene, "[anchor.chest]"));
  EXPECT_EQ(s.anchors[1].name, "base");
  EXPECT_EQ(s.anchors[1].kind, AnchorSpec::Kind::HalfSpace);
  expect_vec(s.anchors[1].normal, 0, 0, -1);
  EXPECT_EQ(s.anchors[2].kind, AnchorSpec::Kind::Box);
  expect_vec(s.anchors[2].max_m, 0.06, 0.06, 0);

  ASSERT_EQ(s.indenters.size(), 2u);
  EXPECT_EQ(s.indenters[0].kind, IndenterSpec::Kind::Sphere);
  EXPECT_DOUBLE_EQ(s.indenters[0].radius_m, 0.005);
  expect_vec(s.indenters[0].velocity_m_s, 0, 0, -0.001);
  EXPECT_DOUBLE_EQ(s.indenters[0].travel_time_s, 10);
  EXPECT_EQ(s.indenters[1].kind, IndenterSpec::Kind::Plate);
  expect_vec(s.indenters[1].velocity_m_s, 0, 0, 0);
  EXPECT_TRUE(std::isinf(s.indenters[1].travel_time_s));
  EXPECT_EQ(s.indenters[0].contact, IndenterSpec::Contact::Push) << "the default";
  EXPECT_EQ(s.indenters[1].contact, IndenterSpec::Contact::Slide);

  ASSERT_EQ(s.tracks.size(), 2u);
  EXPECT_EQ(s.tracks[1].name, "lateral");
  expect_vec(s.tracks[1].point_m, 0.04, 0, 0.02);
  EXPECT_EQ(s.tracks[1].line, line_of(kFullScene, "[[track]]", 1));

  EXPECT_DOUBLE_EQ(s.stop.equilibrium, 1e-5);
  EXPECT_EQ(s.stop.max_steps, 5000000000);
  EXPECT_DOUBLE_EQ(s.stop.max_time_s, 2.5);
  EXPECT_EQ(s.output.frames_every, 100);
}

TEST(SceneFile, AbsentSectionsKeepDefaults) {
  const Scene s = parse_scene_text(kBase, "scene.toml");
  const Scene defaults;
  EXPECT_FALSE(s.gravity.active);
  EXPECT_TRUE(s.anchors.empty() && s.indenters.empty() && s.tracks.empty());
  EXPECT_EQ(s.solver.integrator, defaults.solver.integrator);
  EXPECT_FALSE(s.solver.dt_s.has_value());
  EXPECT_EQ(s.stop.max_steps, defaults.stop.max_steps);
  EXPECT_EQ(s.model.downsample, 1);
  EXPECT_FALSE(s.volume.preserve);
  EXPECT_EQ(s.volume.every, 1);
  EXPECT_EQ(s.volume.predictor, VolumeSpec::Predictor::Pressure);
  EXPECT_TRUE(s.source_path.empty());
}

TEST(SceneFile, VolumeSectionParses) {
  const Scene s = parse_scene_text(kBase + "[volume]\npreserve = true\nevery = 4\n", "scene.toml");
  EXPECT_TRUE(s.volume.preserve);
  EXPECT_EQ(s.volume.every, 4);
  EXPECT_EQ(s.volume.line, 10);
  EXPECT_FALSE(parse_scene_text(kBase + "[volume]\npreserve = false\n", "scene.toml").volume.preserve);
  EXPECT_EQ(s.volume.predictor, VolumeSpec::Predictor::Pressure);
  EXPECT_EQ(parse_scene_text(kBase + "[volume]\npreserve = true\npredictor = \"projection\"\n", "scene.toml").volume.predictor,
            VolumeSpec::Predictor::Projection);
}

TEST(SceneFile, ReferenceStateAndReproducibilitySectionsParse) {
  const Scene s = parse_scene_text(kBase +
                                       "[gravity]\nposture = \"prone\"\n"
                                       "[anchor.chest]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0.01\n"
                                       "[reference_state]\nct_posture = \"supine\"\ntolerance_mm = 0.02\n"
                                       "[reproducibility]\nperturbations = 5\nmax_angle_deg = 2\nseed = 7\n",
                                   "scene.toml");
  EXPECT_TRUE(s.reference_state.active);
  EXPECT_EQ(s.reference_state.ct_posture, "supine");
  EXPECT_NEAR(s.reference_state.ct_gravity_m_s2.y(), 9.80665, 1e-12);
  EXPECT_DOUBLE_EQ(s.reference_state.tolerance_m, 2e-5);
  EXPECT_EQ(s.reference_state.max_iterations, 20);
  EXPECT_TRUE(s.reproducibility.active);
  EXPECT_EQ(s.reproducibility.perturbations, 5);
  EXPECT_DOUBLE_EQ(s.reproducibility.max_angle_deg, 2.0);
  EXPECT_EQ(s.reproducibility.seed, 7u);
  const Scene plain = parse_scene_text(kBase, "scene.toml");
  EXPECT_FALSE(plain.reference_state.active);
  EXPECT_FALSE(plain.reproducibility.active);
}

TEST(SceneFile, DtAutoAndGravityVector) {
  const Scene s = parse_scene_text(
      kBase + "[solver]\ndt = \"auto\"\n[gravity]\nvector = [0, 0, -9.81]\n", "scene.toml");
  EXPECT_FALSE(s.solver.dt_s.has_value());
  EXPECT_TRUE(s.gravity.active);
  EXPECT_TRUE(s.gravity.posture.empty());
  expect_vec(s.gravity.acceleration_m_s2, 0, 0, -9.81);
}

TEST(SceneFile, ReadsFileAndRecordsPath) {
  const auto path = std::filesystem::temp_directory_path() / "voxbreast_test_scene.toml";
  std::ofstream(path) << kBase;
  const Scene s = parse_scene_file(path.string());
  std::filesystem::remove(path);
  EXPECT_EQ(s.source_path, path.string());
  EXPECT_EQ(s.source_text, kBase);
}

TEST(SceneFile, BiphasicSpringKeysParse) {
  const Scene s = parse_scene_text(
      with("E = 3000.0", "law = \"biphasic\"\nE = 3000.0\ncubic = 20\ncritical_strain = 0.1"), "scene.toml");
  const MaterialSpec& m = s.materials.at("adipose");
  EXPECT_EQ(m.law, "biphasic");
  EXPECT_DOUBLE_EQ(m.youngs_modulus_pa, 3000);
  EXPECT_DOUBLE_EQ(m.cubic, 20);  // integer accepted
  EXPECT_DOUBLE_EQ(m.critical_strain, 0.1);
  // "biphasic_spring" names the same law; a default tissue keeps its E; c3 = 0 is allowed.
  const Scene alias = parse_scene_text(
      with("E = 3000.0", "law = \"biphasic_spring\"\ncubic = 0\ncritical_strain = 0.25"), "scene.toml");
  const MaterialSpec& a = alias.materials.at("adipose");
  EXPECT_EQ(a.law, "biphasic");
  EXPECT_GT(a.youngs_modulus_pa, 0);
  EXPECT_DOUBLE_EQ(a.cubic, 0);
  EXPECT_DOUBLE_EQ(a.critical_strain, 0.25);
}

TEST(SceneFile, MissingFileErrorNamesPath) {
  const std::string path = "/nonexistent/voxbreast/scene.toml";
  try {
    parse_scene_file(path);
    FAIL() << "no error for a missing file";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

// ---- every error class: the message names the key and the line -------------------------------

struct ErrorCase {
  std::string name;
  std::string text;
  std::string key;                  ///< dotted key the message must name ("" for syntax errors)
  int line;                         ///< line the message must name
  std::vector<std::string> extras;  ///< further fragments the message must hold
};

void PrintTo(const ErrorCase& c, std::ostream* os) {
  *os << c.name << " (key '" << c.key << "', line " << c.line << ")\n" << c.text;
}

// One case per entry: name, scene text, key and line the message must name, other fragments.
// clang-format off
std::vector<ErrorCase> error_cases() {
  const std::string track = "[[track]]\nname = \"apex\"\npoint = [0, 0, 0]\n";  // 3 lines
  return {
      {"UnknownKey", kBase + "[solver]\nintegrater = \"heun\"\n", "solver.integrater", 11,
       {"unknown key", "did you mean 'integrator'?"}},
      {"UnknownMaterialKey", with("E = 3000.0", "E = 3000.0\ndensty = 900.0"),
       "materials.adipose.densty", 10, {"did you mean 'density'?"}},
      {"UnknownTopLevelTable", kBase + "[materails.x]\nE = 1.0\n", "materails", 10,
       {"did you mean 'materials'?"}},
      {"KeyNotForShapeKind", with("label = \"adipose\"", "label = \"adipose\"\nradius = 0.01"),
       "model.shape[0].radius", 8, {"does not apply to kind 'box'"}},
      {"UnknownKeyInShape", with("label = \"adipose\"", "label = \"adipose\"\nlabl = \"skin\""),
       "model.shape[0].labl", 8, {"unknown key for kind 'box'", "did you mean 'label'?"}},
      {"WrongTypeString", kBase + "[solver]\ndamping = \"lots\"\n", "solver.damping", 11,
       {"expected a number, got a string"}},
      {"WrongArrayLength", with("max = [0.02, 0.02, 0.02]", "max = [0.02, 0.02]"),
       "model.shape[0].max", 6, {"array of 3 numbers"}},
      {"FloatForInteger", kBase + "[solver]\ncheck_every = 10.0\n", "solver.check_every", 11,
       {"expected an integer"}},
      {"NegativeModulus", with("E = 3000.0", "E = -5.0"), "materials.adipose.E", 9, {"> 0"}},
      {"InfiniteModulus", with("E = 3000.0", "E = inf"), "materials.adipose.E", 9, {"finite"}},
      {"ModulusBeyondAnyMaterial", with("E = 3000.0", "E = 1e30"), "materials.adipose.E", 9, {"at most 1e+13 Pa", "diamond"}},
      {"MissingModulusWithoutDefault",
       with("[materials.adipose]\nE = 3000.0", "[materials.adipose]\nE = 3000.0\n[materials.gel]\ndensity = 900.0"),
       "materials.gel.E", 10, {"missing required key", "no default material"}},
      {"ZeroSpacing", with("spacing = 0.002", "spacing = 0"), "model.spacing", 2, {"> 0"}},
      {"MissingSpacing", with("spacing = 0.002\n", ""), "model.spacing", 1, {"missing"}},
      {"DensityInGramsPerCubicCentimetre", with("E = 3000.0", "E = 3000.0\ndensity = 1.05"),
       "materials.adipose.density", 10, {"[10, 30000] kg/m³, got 1.05", "1.05 g/cm³ is 1050 kg/m³"}},
      {"SpacingInMillimetres", with("spacing = 0.002", "spacing = 2"), "model.spacing", 2,
       {"at most 0.1 (metres), got 2", "2 mm is 0.002"}},
      {"NoShapes", "[model]\nspacing = 0.002\n[materials.adipose]\nE = 3000.0\n", "model.shape", 1,
       {"the model has no shapes"}},
      {"ZeroDownsample", with("spacing = 0.002", "spacing = 0.002\ndownsample = 0"),
       "model.downsample", 3, {"≥ 1"}},
      {"UnknownShapeKind", with("kind = \"box\"", "kind = \"cube\""), "model.shape[0].kind", 4,
       {"accepted: box, sphere"}},
      {"MaxNotAboveMin", with("max = [0.02, 0.02, 0.02]", "max = [0.02, 0, 0.02]"),
       "model.shape[0].max", 6, {"exceed"}},
      {"LabelWithoutMaterial", with("label = \"adipose\"", "label = \"glandular\""),
       "model.shape[0].label", 3, {"glandular"}},
      {"ImageAndShapes", with("spacing = 0.002", "spacing = 0.002\nimage = \"ct.nii.gz\""),
       "model.image", 3, {"not both"}},
      {"ImageWithoutClassification", "[model]\nimage = \"ct.nii.gz\"\n", "model.image", 2,
       {"labels", "hu_class"}},
      {"LabelTableKeyNotANumber",
       "[model]\nimage = \"ct.nii.gz\"\nlabels = \"l.nii.gz\"\n[model.label_table]\nfat = \"adipose\"\n",
       "model.label_table.fat", 5, {"label values"}},
      {"HuClassMaxBelowMin",
       "[model]\nimage = \"ct.nii.gz\"\n[[model.hu_class]]\ntissue = \"adipose\"\nmin = 0\nmax = -100\n",
       "model.hu_class[0].max", 6, {"greater than min"}},
      {"RoiMinWithoutMax",
       "[model]\nimage = \"ct.nii.gz\"\nroi_min = [0, 0, 0]\n[[model.hu_class]]\ntissue = \"adipose\"\nmin = -200\nmax = 0\n",
       "model.roi_max", 1, {"go together"}},
      {"ShapeModelWithImageKey", with("spacing = 0.002", "spacing = 0.002\nkeep = [\"adipose\"]"),
       "model.keep", 3, {"image models only"}},
      {"BothVectorAndPosture", kBase + "[gravity]\nvector = [0, 0, -9.81]\nposture = \"prone\"\n",
       "gravity.posture", 12, {"not both"}},
      {"UnknownPosture", kBase + "[gravity]\nposture = \"sideways\"\n", "gravity.posture", 11,
       {"unknown posture 'sideways'", "supine, prone, upright, left_lateral, right_lateral"}},
      {"MagnitudeWithVector", kBase + "[gravity]\nvector = [0, 0, -9.81]\nmagnitude = 3.0\n",
       "gravity.magnitude", 12, {"only with 'posture'"}},
      {"BiphasicWithoutCubic", with("E = 3000.0", "law = \"biphasic\"\nE = 3000.0\ncritical_strain = 0.1"),
       "materials.adipose.cubic", 8, {"missing required key"}},
      {"BiphasicWithoutCriticalStrain", with("E = 3000.0", "law = \"biphasic\"\nE = 3000.0\ncubic = 20.0"),
       "materials.adipose.critical_strain", 8, {"missing required key"}},
      {"BiphasicNegativeCubic", with("E = 3000.0", "law = \"biphasic\"\nE = 3000.0\ncubic = -1.0\ncritical_strain = 0.1"),
       "materials.adipose.cubic", 11, {"≥ 0"}},
      {"BiphasicCriticalStrainOne", with("E = 3000.0", "law = \"biphasic\"\nE = 3000.0\ncubic = 20.0\ncritical_strain = 1.0"),
       "materials.adipose.critical_strain", 12, {"(0, 1)"}},
      {"BiphasicCriticalStrainZero", with("E = 3000.0", "law = \"biphasic\"\ncubic = 20.0\ncritical_strain = 0"),
       "materials.adipose.critical_strain", 11, {"(0, 1)"}},
      {"BiphasicCriticalStrainNotANumber", with("E = 3000.0", "law = \"biphasic\"\ncubic = 20.0\ncritical_strain = \"10%\""),
       "materials.adipose.critical_strain", 11, {"expected a number"}},
      {"CubicOnLinear", with("E = 3000.0", "E = 3000.0\ncubic = 20.0"), "materials.adipose.cubic", 10,
       {"does not apply to law 'linear'", "keys for this law: E"}},
      {"CriticalStrainOnNeoHookean", with("E = 3000.0", "law = \"neo-hookean\"\nE = 3000.0\ncritical_strain = 0.1"),
       "materials.adipose.critical_strain", 11, {"does not apply to law 'neo-hookean'"}},
      {"NuOnBiphasic", with("E = 3000.0", "law = \"biphasic\"\ncubic = 20.0\ncritical_strain = 0.1\nnu = 0.45"),
       "materials.adipose.nu", 12, {"Poisson ratio 0.25"}},
      {"KeyOfAnotherLaw", with("E = 3000.0", "law = \"neo-hookean\"\nE = 3000.0\nalpha = [2.0]"),
       "materials.adipose.alpha", 11, {"does not apply to law 'neo-hookean'"}},
      {"PoissonRatioAtHalf", with("E = 3000.0", "law = \"neo-hookean\"\nE = 3000.0\nnu = 0.5"),
       "materials.adipose.nu", 11, {"Poisson"}},
      {"OgdenWithoutAlpha", with("E = 3000.0", "law = \"ogden\"\nmu = [1000.0]"),
       "materials.adipose.alpha", 8, {"missing required key"}},
      {"OgdenZeroShearModulus", with("E = 3000.0", "law = \"ogden\"\nmu = [1000.0, -1000.0]\nalpha = [2.0, 2.0]"),
       "materials.adipose.mu", 10, {"shear modulus"}},
      // μ₀ = 0.002 Pa > 0, but C10 + C01/λ < 0 in compression: the stress falls as the strain grows
      {"MooneyRivlinNotStable", with("E = 3000.0", "law = \"mooney-rivlin\"\nc10 = 1000.0\nc01 = -999.999"),
       "materials.adipose.c01", 11, {"not stable", "in uniaxial stress at stretch 0.500"}},
      {"OgdenSoftensInTension", with("E = 3000.0", "law = \"ogden\"\nmu = [3000.0, -500.0]\nalpha = [2.0, 8.0]"),
       "materials.adipose.mu", 10, {"not stable", "in uniaxial stress"}},
      {"LawUnknown", with("E = 3000.0", "law = \"rubber\"\nE = 3000.0"), "materials.adipose.law", 9,
       {"accepted: linear"}},
      {"NuOnLinear", with("E = 3000.0", "E = 3000.0\nnu = 0.45"), "materials.adipose.nu", 10,
       {"Poisson ratio 0.25"}},
      {"BadDt", kBase + "[solver]\ndt = \"fast\"\n", "solver.dt", 11, {"auto"}},
      {"DtSafetyAboveOne", kBase + "[solver]\ndt_safety = 1.5\n", "solver.dt_safety", 11,
       {"(0, 1]"}},
      {"UnknownIntegrator", kBase + "[solver]\nintegrator = \"hewn\"\n", "solver.integrator", 11,
       {"did you mean 'heun'?"}},
      {"AnchorNotATable", kBase + "[anchor]\nkind = \"sphere\"\n", "anchor.kind", 11,
       {"expected a table"}},
      {"AnchorZeroNormal",
       kBase + "[anchor.base]\nkind = \"halfspace\"\npoint = [0, 0, 0]\nnormal = [0, 0, 0]\n",
       "anchor.base.normal", 13, {"nonzero"}},
      {"IndenterWithoutStart", kBase + "[[indenter]]\nkind = \"sphere\"\nradius = 0.005\n",
       "indenter[0].start", 10, {"missing required key"}},
      {"UnknownContact",
       kBase + "[[indenter]]\nkind = \"plate\"\nstart = [0, 0, 0]\nnormal = [0, 0, 1]\ncontact = \"stik\"\n",
       "indenter[0].contact", 14, {"unknown value 'stik'", "did you mean 'stick'?"}},
      {"DuplicateTrackName", kBase + track + track, "track[1].name", 14,
       {"duplicate track name 'apex'", "line 10"}},
      {"OutputDvfNeedsImage", kBase + "[output]\ndvf = true\n", "output.dvf", 11,
       {"needs a CT image model"}},
      {"VolumeUnknownKey", kBase + "[volume]\npreserve = true\nstiffness = 1.0\n", "volume.stiffness", 12,
       {"unknown key"}},
      {"VolumePreserveNotBool", kBase + "[volume]\npreserve = 1\n", "volume.preserve", 11,
       {"true or false"}},
      {"VolumeEveryZero", kBase + "[volume]\npreserve = true\nevery = 0\n", "volume.every", 12,
       {"integer ≥ 1"}},
      {"VolumeEveryFloat", kBase + "[volume]\nevery = 2.0\n", "volume.every", 11,
       {"expected an integer"}},
      {"VolumeUnknownPredictor", kBase + "[volume]\npreserve = true\npredictor = \"projected\"\n",
       "volume.predictor", 12, {"unknown value 'projected'", "accepted: pressure, projection"}},
      {"TomlSyntaxError", kBase + "[solver\n", "", 10, {"TOML syntax error", "scene.toml:10:"}},
      {"ReferenceStateNeedsPosture", kBase + "[gravity]\nposture = \"prone\"\n[reference_state]\ntolerance_mm = 0.01\n",
       "reference_state.ct_posture", 12, {"needs the CT's posture"}},
      {"ReferenceStatePostureAndVector", kBase + "[gravity]\nposture = \"prone\"\n[reference_state]\nct_posture = \"supine\"\nct_gravity = [0, 9.81, 0]\n",
       "reference_state.ct_gravity", 14, {"not both"}},
      {"ReferenceStateUnknownPosture", kBase + "[gravity]\nposture = \"prone\"\n[reference_state]\nct_posture = \"supin\"\n",
       "reference_state.ct_posture", 13, {"supine"}},
      {"ReferenceStateNegativeTolerance", kBase + "[gravity]\nposture = \"prone\"\n[reference_state]\nct_posture = \"supine\"\ntolerance_mm = -1\n",
       "reference_state.tolerance_mm", 14, {}},
      {"ReferenceStateNeedsGravity", kBase + "[reference_state]\nct_posture = \"supine\"\n",
       "reference_state", 10, {"needs a [gravity] section"}},
      {"ReproducibilityNeedsSphere", kBase + "[reproducibility]\nperturbations = 4\n",
       "reproducibility.perturbations", 11, {"sphere anchor"}},
      {"ReproducibilityOnePerturbation", kBase + "[reproducibility]\nperturbations = 1\n",
       "reproducibility.perturbations", 11, {"integer ≥ 2"}},
      {"ReproducibilityAngleTooLarge", kBase + "[anchor.chest]\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0.01\n[reproducibility]\nmax_angle_deg = 60\n",
       "reproducibility.max_angle_deg", 15, {"at most 45"}},
  };
}
// clang-format on

class SceneFileError : public ::testing::TestWithParam<ErrorCase> {};

TEST_P(SceneFileError, MessageNamesKeyAndLine) {
  const ErrorCase& c = GetParam();
  try {
    parse_scene_text(c.text, "scene.toml");
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string message = e.what();
    const std::string at = "scene.toml:" + std::to_string(c.line);
    const bool names_line =
        message.find(at + " ") != std::string::npos || message.find(at + ":") != std::string::npos;
    EXPECT_TRUE(names_line) << "no '" << at << "' in: " << message;
    if (!c.key.empty()) {
      EXPECT_NE(message.find("'" + c.key + "'"), std::string::npos) << "no key in: " << message;
    }
    for (const std::string& fragment : c.extras) {
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "no '" << fragment << "' in: " << message;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, SceneFileError, ::testing::ValuesIn(error_cases()),
                         [](const auto& info) { return info.param.name; });

// ---- postures: LPS body frame ----------------------------------------------------------------

struct PostureCase {
  std::string name;
  Vec3 expected;
};

void PrintTo(const PostureCase& c, std::ostream* os) {
  *os << c.name << " → (" << c.expected.transpose() << ")";
}

class Posture : public ::testing::TestWithParam<PostureCase> {};

TEST_P(Posture, GravityInBodyFrame) {
  const PostureCase& c = GetParam();
  const Scene s =
      parse_scene_text(kBase + "[gravity]\nposture = \"" + c.name + "\"\n", "scene.toml");
  EXPECT_TRUE(s.gravity.active);
  EXPECT_EQ(s.gravity.posture, c.name);
  expect_vec(s.gravity.acceleration_m_s2, c.expected.x(), c.expected.y(), c.expected.z());
  expect_vec(gravity_for_posture(c.name), c.expected.x(), c.expected.y(), c.expected.z());
}

INSTANTIATE_TEST_SUITE_P(All, Posture,
                         ::testing::Values(PostureCase{"supine", {0, g, 0}},
                                           PostureCase{"prone", {0, -g, 0}},
                                           PostureCase{"upright", {0, 0, -g}},
                                           PostureCase{"left_lateral", {g, 0, 0}},
                                           PostureCase{"right_lateral", {-g, 0, 0}}),
                         [](const auto& info) { return info.param.name; });

TEST(PostureNames, ListsEveryPostureAndRejectsOthers) {
  EXPECT_EQ(posture_names().size(), 5u);
  EXPECT_THROW(gravity_for_posture("Supine"), Error);
}

// ---- the committed sample scenes -------------------------------------------------------------

TEST(SampleScenes, EveryDataSampleSceneParses) {
  const std::filesystem::path samples =
      std::filesystem::path(VOXBREAST_SOURCE_DIR) / "data-samples";
  std::vector<std::filesystem::path> scenes;
  if (std::filesystem::is_directory(samples)) {
    for (const auto& entry : std::filesystem::recursive_directory_iterator(samples)) {
      if (entry.is_regular_file() && entry.path().extension() == ".toml") scenes.push_back(entry);
    }
  }
  if (scenes.empty()) GTEST_SKIP() << "no *.toml under " << samples;
  for (const auto& path : scenes) {
    try {
      parse_scene_file(path.string());
    } catch (const Error& e) {
      ADD_FAILURE() << e.what();
    }
  }
}

}  // namespace
}  // namespace vb

namespace vb {
namespace {

TEST(SceneFileImage, ReadsAnImageModelWithDefaultsAndRelativePaths) {
  const std::string dir = ::testing::TempDir() + "/voxbreast_scene_image";
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/scene.toml";
  std::ofstream(path) << "[model]\nimage = \"ct.nii.gz\"\nlabels = \"labels.nii.gz\"\nkeep = [\"adipose\", \"bone\"]\n"
                         "roi_min = [-0.1, -0.1, -0.1]\nroi_max = [0.1, 0.0, 0.1]\n"
                         "[model.label_table]\n2 = \"adipose\"\n5 = \"bone\"\n"
                         "[materials.adipose]\nE = 4000.0\n";
  const Scene s = parse_scene_file(path);
  EXPECT_TRUE(s.model.from_image());
  EXPECT_EQ(s.model.image_path, (std::filesystem::path(dir) / "ct.nii.gz").lexically_normal().string());
  EXPECT_EQ(s.model.label_table.at(5), "bone");
  ASSERT_TRUE(s.model.roi_m.has_value());
  EXPECT_EQ(s.model.roi_m->second.y(), 0.0);
  EXPECT_EQ(s.materials.at("adipose").youngs_modulus_pa, 4000.0);  // override
  EXPECT_EQ(s.materials.at("adipose").density_kg_m3, 950.0);       // default kept
  EXPECT_TRUE(s.materials.at("bone").rigid);                        // default material filled in
  EXPECT_EQ(s.model.spacing_m, 0.0);                                // image's own spacing
}

}  // namespace
}  // namespace vb

namespace vb {
namespace {

TEST(SceneFile, RelaxationIntegratorRunsCloserToTheStabilityLimit) {
  const Scene relax = parse_scene_text(kBase + "[solver]\nintegrator = \"relaxation\"\n", "relax.toml");
  EXPECT_EQ(relax.solver.integrator, Integrator::Relaxation);
  EXPECT_DOUBLE_EQ(relax.solver.dt_safety, 0.9);  // its default; the others keep 0.5
  EXPECT_DOUBLE_EQ(parse_scene_text(kBase, "base.toml").solver.dt_safety, 0.5);
  const Scene given = parse_scene_text(kBase + "[solver]\nintegrator = \"relaxation\"\ndt_safety = 0.6\n", "r.toml");
  EXPECT_DOUBLE_EQ(given.solver.dt_safety, 0.6);
}

}  // namespace
}  // namespace vb
