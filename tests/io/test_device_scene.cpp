// [[device.torus]] and [positioning] in scene files: values read in SI, and every bad value
// rejected with its key and line.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "engine/device/torus.hpp"
#include "engine/error.hpp"
#include "io/scene_file.hpp"

namespace vb {
namespace {

// A minimal valid scene; the cases below count lines from it.
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

const std::string kTorus =
    "[[device.torus]]\n"              // 10
    "center = [0.01, 0.01, 0.01]\n"   // 11
    "axis = [0, 0, 2]\n"              // 12
    "major_radius = 0.02\n"           // 13
    "minor_radius = 0.005\n";         // 14

std::string torus_with(const std::string& from, const std::string& to) {
  std::string text = kTorus;
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("torus text lacks '" + from + "'");
  return kBase + text.replace(at, from.size(), to);
}

TEST(DeviceScene, ReadsToriInSiWithSchedulesAndDefaults) {
  const Scene s = parse_scene_text(kBase + kTorus +
                                       "[[device.torus]]\n"
                                       "name = \"upper\"\n"
                                       "center = [0, 0, 0.03]\n"
                                       "axis = [1, 0, 0]\n"
                                       "major_radius = 0.05\n"
                                       "inflate = [[0, 0.004], [1.5, 0.012], [2, 0.012]]\n"
                                       "friction = 0.4\n"
                                       "[[device.torus]]\n"
                                       "center = [0, 0, 0]\n"
                                       "axis = [0, 1, 0]\n"
                                       "inner_outer = [[0, 0.04, 0.05], [1, 0.03, 0.06]]\n"
                                       "[anchor.chest]\nkind = \"sphere\"\ncenter = [0, 0.2, 0]\nradius = 0.2\n"
                                       "[positioning]\ntumour_tissue = \"adipose\"\ntarget = [0, -0.01, 0]\n"
                                       "chest_wall = \"chest\"\n",
                                   "scene.toml");
  ASSERT_EQ(s.tori.size(), 3u);
  EXPECT_EQ(s.tori[0].name, "torus_1");  // default names count from 1
  EXPECT_NEAR(s.tori[0].axis.z(), 1.0, 1e-15);  // normalised
  ASSERT_EQ(s.tori[0].schedule.size(), 1u);
  EXPECT_DOUBLE_EQ(s.tori[0].schedule[0].minor_radius_m, 0.005);
  EXPECT_DOUBLE_EQ(s.tori[0].friction, 0.0);
  EXPECT_EQ(s.tori[1].name, "upper");
  EXPECT_DOUBLE_EQ(s.tori[1].friction, 0.4);
  ASSERT_EQ(s.tori[1].schedule.size(), 3u);
  EXPECT_DOUBLE_EQ(s.tori[1].schedule[1].time_s, 1.5);
  EXPECT_DOUBLE_EQ(s.tori[1].schedule[1].major_radius_m, 0.05);
  const TorusRadii mid = torus_radii(s.tori[1], 0.75);
  EXPECT_NEAR(mid.minor_m, 0.008, 1e-15);
  EXPECT_NEAR(mid.minor_rate_m_s, 0.008 / 1.5, 1e-15);
  EXPECT_DOUBLE_EQ(torus_radii(s.tori[1], 9).minor_m, 0.012);
  EXPECT_DOUBLE_EQ(torus_radii(s.tori[1], 9).minor_rate_m_s, 0.0);
  EXPECT_DOUBLE_EQ(torus_inflation_end_s(s.tori[1]), 2.0);
  EXPECT_EQ(s.tori[2].name, "torus_3");
  // inner/outer → R = (inner + outer)/2, r = (outer − inner)/2
  EXPECT_NEAR(s.tori[2].schedule[1].major_radius_m, 0.045, 1e-15);
  EXPECT_NEAR(s.tori[2].schedule[1].minor_radius_m, 0.015, 1e-15);
  EXPECT_EQ(s.positioning.tumour_tissue, "adipose");
  ASSERT_TRUE(s.positioning.target_m.has_value());
  EXPECT_DOUBLE_EQ(s.positioning.target_m->y(), -0.01);
  EXPECT_EQ(s.positioning.chest_wall, "chest");
}

struct ErrorCase {
  std::string name, text, key;
  int line;
  std::vector<std::string> extras;
};

void PrintTo(const ErrorCase& c, std::ostream* os) { *os << c.name; }

// clang-format off
std::vector<ErrorCase> error_cases() {
  const std::string t = "device.torus[0].";
  return {
      {"NegativeMinorRadius", torus_with("minor_radius = 0.005", "minor_radius = -0.005"), t + "minor_radius", 14, {"> 0"}},
      {"MinorNotBelowMajor", torus_with("minor_radius = 0.005", "minor_radius = 0.02"), t + "minor_radius", 14,
       {"smaller than the major radius"}},
      {"ZeroAxis", torus_with("axis = [0, 0, 2]", "axis = [0, 0, 0]"), t + "axis", 12, {"nonzero"}},
      {"MissingCenter", torus_with("center = [0.01, 0.01, 0.01]\n", ""), t + "center", 10, {"missing required key"}},
      {"MissingMajorRadius", torus_with("major_radius = 0.02\n", ""), t + "major_radius", 10, {"missing required key"}},
      {"MissingTubeSize", torus_with("minor_radius = 0.005\n", ""), t + "minor_radius", 10, {"missing the tube size"}},
      {"MinorAndInflate", kBase + kTorus + "inflate = [[0, 0.005]]\n", t + "inflate", 15, {"only one of"}},
      {"InflateTimesNotIncreasing", torus_with("minor_radius = 0.005", "inflate = [[0, 0.004], [0, 0.006]]"),
       t + "inflate", 14, {"increase strictly"}},
      {"InflateNegativeTime", torus_with("minor_radius = 0.005", "inflate = [[-1, 0.004]]"), t + "inflate", 14, {"≥ 0 s"}},
      {"InflateRowOfThree", torus_with("minor_radius = 0.005", "inflate = [[0, 0.004, 1]]"), t + "inflate", 14,
       {"row 1", "[t_s, minor_radius_m]"}},
      {"InflateNotRows", torus_with("minor_radius = 0.005", "inflate = [0, 0.004]"), t + "inflate", 14, {"row 1"}},
      {"InflateZeroRadius", torus_with("minor_radius = 0.005", "inflate = [[0, 0.004], [1, 0]]"), t + "inflate", 14,
       {"t = 1 s", "> 0"}},
      {"InflateReachesMajor", torus_with("minor_radius = 0.005", "inflate = [[0, 0.004], [1, 0.03]]"), t + "inflate", 14,
       {"smaller than the major radius", "t = 1 s"}},
      {"InnerOuterWithMajor", torus_with("minor_radius = 0.005", "inner_outer = [[0, 0.01, 0.02]]"), t + "major_radius", 13,
       {"'inner_outer' sets the major radius"}},
      {"InnerAboveOuter", torus_with("major_radius = 0.02\nminor_radius = 0.005", "inner_outer = [[0, 0.03, 0.02]]"),
       t + "inner_outer", 13, {"0 < inner < outer"}},
      {"NegativeFriction", kBase + kTorus + "friction = -0.1\n", t + "friction", 15, {"≥ 0"}},
      {"MisspeltKey", torus_with("minor_radius", "minor_radus"), t + "minor_radus", 14, {"did you mean 'minor_radius'?"}},
      {"BadName", kBase + kTorus + "name = \"left ring\"\n", t + "name", 15, {"letters, digits"}},
      {"DuplicateName", kBase + kTorus + "name = \"ring\"\n" + kTorus + "name = \"ring\"\n", "device.torus[1].name", 21,
       {"duplicate torus name 'ring'", "line 10"}},
      {"DeviceUnknownKey", kBase + "[device]\nkind = \"torus\"\n", "device.kind", 11, {"unknown key"}},
      {"DeviceTorusNotArray", kBase + "[device.torus]\ncenter = [0, 0, 0]\n", "device.torus", 10, {"array of tables"}},
      {"PositioningUnknownAnchor", kBase + "[positioning]\nchest_wall = \"chest\"\n", "positioning.chest_wall", 11,
       {"names no [anchor.chest]"}},
      {"PositioningBoxAnchor",
       kBase + "[anchor.chest]\nkind = \"box\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\n[positioning]\nchest_wall = \"chest\"\n",
       "positioning.chest_wall", 15, {"is a box"}},
      {"PositioningMisspeltKey", kBase + "[positioning]\ntumor_tissue = \"tumour\"\n", "positioning.tumor_tissue", 11,
       {"did you mean 'tumour_tissue'?"}},
      {"PositioningTargetNotVector", kBase + "[positioning]\ntarget = 0.01\n", "positioning.target", 11,
       {"array of 3 numbers"}},
  };
}
// clang-format on

class DeviceSceneError : public ::testing::TestWithParam<ErrorCase> {};

TEST_P(DeviceSceneError, MessageNamesKeyAndLine) {
  const ErrorCase& c = GetParam();
  try {
    parse_scene_text(c.text, "scene.toml");
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string message = e.what();
    const std::string at = "scene.toml:" + std::to_string(c.line);
    EXPECT_TRUE(message.find(at + " ") != std::string::npos) << "no '" << at << "' in: " << message;
    EXPECT_NE(message.find("'" + c.key + "'"), std::string::npos) << "no key in: " << message;
    for (const std::string& fragment : c.extras)
      EXPECT_NE(message.find(fragment), std::string::npos) << "no '" << fragment << "' in: " << message;
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, DeviceSceneError, ::testing::ValuesIn(error_cases()),
                         [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace vb
