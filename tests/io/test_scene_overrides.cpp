#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "engine/error.hpp"
#include "io/scene_file.hpp"
#include "io/scene_overrides.hpp"

namespace vb {
namespace {

const std::string kScene = R"(# a block; comments and order must survive an override
[model]
spacing = 0.002   # 2 mm

[[model.shape]]
kind = "box"
min = [0.0, 0.0, 0.0]
max = [0.01, 0.01, 0.01]
label = "soft"

[[model.shape]]
kind = "sphere"
center = [0.005, 0.005, 0.005]
radius = 0.002
label = "stiff"

[materials.soft]
E = 3000.0

[materials.stiff]
E = 30000.0

[gravity]
vector = [0.0, 0.0, -9.81]

[anchor.chest]
kind = "sphere"
center = [0.0, 0.0, -0.1]
radius = 0.101
rpy_deg = [0.0, 0.0, 0.0]

[[track]]
name = "top"   # the name "top" is used by tests
point = [0.005, 0.005, 0.01]
)";

std::string apply(const std::vector<SceneOverride>& overrides, const std::string& text = kScene) {
  return apply_scene_overrides(text, "scene.toml", overrides);
}

/// The vb::Error text of applying `overrides`, or "" when it succeeds.
std::string error_of(const std::vector<SceneOverride>& overrides, const std::string& text = kScene) {
  try {
    apply(overrides, text);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(SceneOverrides, ChangesOnlyTheValueAndKeepsEverythingElse) {
  const std::string out = apply({{"materials.soft.E", "4500", false}});
  std::string expected = kScene;
  expected.replace(expected.find("E = 3000.0"), 10, "E = 4500");
  EXPECT_EQ(out, expected);
  EXPECT_DOUBLE_EQ(parse_scene_text(out, "case").materials.at("soft").youngs_modulus_pa, 4500);
}

TEST(SceneOverrides, AddressesArrayElementsFromOne) {
  const Scene s = parse_scene_text(apply({{"gravity.vector.2", "-1.5", false},
                                          {"anchor.chest.rpy_deg.1", "5.0", false},
                                          {"model.shape.2.radius", "0.003", false},
                                          {"track.1.point.3", "0.009", false}}),
                                   "case");
  EXPECT_DOUBLE_EQ(s.gravity.acceleration_m_s2.y(), -1.5);
  EXPECT_DOUBLE_EQ(s.gravity.acceleration_m_s2.z(), -9.81);
  EXPECT_DOUBLE_EQ(s.anchors.at(0).rpy_deg.x(), 5.0);
  EXPECT_DOUBLE_EQ(s.model.shapes.at(1).radius_m, 0.003);
  EXPECT_DOUBLE_EQ(s.model.shapes.at(0).max_m.x(), 0.01);  // the other shape is untouched
  EXPECT_DOUBLE_EQ(s.tracks.at(0).point_m.z(), 0.009);
}

TEST(SceneOverrides, ReplacesWholeArraysAndStrings) {
  const Scene s = parse_scene_text(
      apply({{"gravity.vector", "[0, -9.81, 0]", false}, {"track.1.name", "\"apex\"", false}}), "case");
  EXPECT_DOUBLE_EQ(s.gravity.acceleration_m_s2.y(), -9.81);
  EXPECT_EQ(s.tracks.at(0).name, "apex");
}

TEST(SceneOverrides, MissingKeyIsAnErrorWithAHint) {
  EXPECT_NE(error_of({{"materials.soft.Ee", "1", false}}).find("did you mean 'E'?"), std::string::npos);
  EXPECT_NE(error_of({{"materials.sotf.E", "1", false}}).find("no such key in the scene: 'materials.sotf'"),
            std::string::npos);
  const std::string e = error_of({{"solver.dt", "1e-4", false}});
  EXPECT_NE(e.find("+solver.dt"), std::string::npos) << e;  // says how to add it
}

TEST(SceneOverrides, BadIndicesAndTablesAreErrors) {
  EXPECT_NE(error_of({{"gravity.vector.4", "1", false}}).find("has 3 elements"), std::string::npos);
  EXPECT_NE(error_of({{"gravity.vector.0", "1", false}}).find("numbered from 1"), std::string::npos);
  EXPECT_NE(error_of({{"gravity.vector.x", "1", false}}).find("numbered from 1"), std::string::npos);
  EXPECT_NE(error_of({{"track.2.name", "\"b\"", false}}).find("has 1 element"), std::string::npos);
  EXPECT_NE(error_of({{"materials.soft", "1", false}}).find("is a table"), std::string::npos);
  EXPECT_NE(error_of({{"track", "1", false}}).find("array of tables"), std::string::npos);
  EXPECT_NE(error_of({{"model.spacing.x", "1", false}}).find("is a number, it has no key 'x'"), std::string::npos);
}

TEST(SceneOverrides, OverlapsAndBadValuesAreErrors) {
  EXPECT_NE(error_of({{"gravity.vector", "[0, 0, 1]", false}, {"gravity.vector.3", "1", false}}).find("overlaps"),
            std::string::npos);
  EXPECT_NE(error_of({{"model.spacing", "0.1 0.2", false}}).find("not a TOML value"), std::string::npos);
}

TEST(SceneOverrides, AddsKeysInExistingAndNewTables) {
  const std::string out = apply({{"materials.soft.density", "900", true},
                                 {"track.1.name", "\"apex\"", false},
                                 {"solver.dt", "1e-4", true},
                                 {"solver.integrator", "\"symplectic_euler\"", true},
                                 {"anchor.chest.radius", "0.102", true}});  // exists: replaced
  const Scene s = parse_scene_text(out, "case");
  EXPECT_DOUBLE_EQ(s.materials.at("soft").density_kg_m3, 900);
  EXPECT_DOUBLE_EQ(*s.solver.dt_s, 1e-4);
  EXPECT_EQ(s.solver.integrator, Integrator::SymplecticEuler);
  EXPECT_DOUBLE_EQ(s.anchors.at(0).radius_m, 0.102);
  EXPECT_NE(out.find("[materials.soft]\ndensity = 900\nE = 3000.0"), std::string::npos) << out;
  EXPECT_NE(out.find("\n[solver]\ndt = 1e-4\nintegrator = \"symplectic_euler\"\n"), std::string::npos) << out;
}

TEST(SceneOverrides, AddsKeysInArrayOfTablesEntries) {
  const std::string out = apply({{"model.shape.2.label", "\"soft\"", false}, {"track.1.extra", "1", true}});
  EXPECT_NE(out.find("[[track]]\nextra = 1\n"), std::string::npos) << out;
  // The strict parser still sees the added key.
  EXPECT_THROW(parse_scene_text(out, "case"), Error);
  EXPECT_NE(error_of({{"track.1.sub.key", "1", true}}).find("inside an array entry"), std::string::npos);
}

TEST(SceneOverrides, AddedKeysStillGoThroughTheStrictParser) {
  try {
    parse_scene_text(apply({{"materials.soft.Ee", "1", true}}), "case");
    FAIL() << "an added unknown key must be refused by the scene parser";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("materials.soft.Ee"), std::string::npos) << e.what();
  }
}

TEST(SceneOverrides, QuotedKeysAndNonAsciiText) {
  const std::string text = "[materials.\"my tissue\"]\nname = \"héllo wörld\"\nE = 3000.0\n";
  EXPECT_EQ(apply({{"materials.\"my tissue\".E", "5", false}, {"materials.\"my tissue\".name", "\"ö\"", false}}, text),
            "[materials.\"my tissue\"]\nname = \"ö\"\nE = 5\n");
  // toml++ counts columns in code points: a value after multi-byte characters on its line.
  EXPECT_EQ(apply({{"t.b", "5", false}}, "t = { \"ä\" = \"öö\", b = 2 }\n"), "t = { \"ä\" = \"öö\", b = 5 }\n");
}

TEST(SceneOverrides, EditsAreCheckedByParsingAgain) {
  // A dotted-key table cannot be reopened by an appended [header]: refused, never mis-edited.
  const std::string text = "[anchor]\nchest.kind = \"sphere\"\n";
  EXPECT_NE(error_of({{"anchor.chest.radius", "0.1", true}}, text).find("could not be edited"), std::string::npos);
}

TEST(SceneKeys, SplitsDotsOutsideQuotes) {
  EXPECT_EQ(split_scene_key("a.b.3"), (std::vector<std::string>{"a", "b", "3"}));
  EXPECT_EQ(split_scene_key("materials.\"a.b\".E"), (std::vector<std::string>{"materials", "a.b", "E"}));
  EXPECT_THROW(split_scene_key("a..b"), Error);
  EXPECT_THROW(split_scene_key(".a"), Error);
  EXPECT_THROW(split_scene_key("a.\"b"), Error);
}

TEST(SceneValues, WordsBecomeStringsAndTomlStaysAsWritten) {
  EXPECT_EQ(toml_value_text("prone"), "'prone'");
  EXPECT_EQ(toml_value_text("\"prone\""), "\"prone\"");
  EXPECT_EQ(toml_value_text(" 3000 "), "3000");
  EXPECT_EQ(toml_value_text("1e-4"), "1e-4");
  EXPECT_EQ(toml_value_text("true"), "true");
  EXPECT_EQ(toml_value_text("[0, 0, -9.81]"), "[0, 0, -9.81]");
  EXPECT_EQ(toml_value_text("it's"), "\"it's\"");
  EXPECT_THROW(toml_value_text("nan"), Error);
  EXPECT_THROW(toml_value_text("[1, inf]"), Error);
  EXPECT_THROW(toml_value_text("{a = 1}"), Error);
  EXPECT_THROW(toml_value_text("  "), Error);
  EXPECT_EQ(toml_value_plain("'prone'"), "prone");
  EXPECT_EQ(toml_value_plain("[1, 2]"), "[1, 2]");
}

TEST(SceneSettings, ParsesOneKeyAndOneValue) {
  const SceneOverride e = parse_scene_setting("materials.soft.E=4500");
  EXPECT_EQ(e.key, "materials.soft.E");
  EXPECT_EQ(e.value, "4500");
  EXPECT_FALSE(e.add);
  const SceneOverride posture = parse_scene_setting(" +gravity.posture = prone");
  EXPECT_EQ(posture.key, "gravity.posture");
  EXPECT_EQ(posture.value, "'prone'");
  EXPECT_TRUE(posture.add);
  EXPECT_EQ(parse_scene_setting("gravity.vector=[0, -9.81, 0]").value, "[0, -9.81, 0]");
  EXPECT_EQ(parse_scene_setting("track.1.name=a,b").value, "'a,b'");  // one value: commas do not split
  for (const char* bad : {"materials.soft.E", "=3", "+=3", "a..b=1", "a.b=", "a.b=nan", "a.b={x = 1}"}) {
    try {
      parse_scene_setting(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const Error& error) {
      EXPECT_NE(std::string(error.what()).find(std::string("--set ") + bad), std::string::npos) << error.what();
    }
  }
}

TEST(SceneSettings, AFileReadWithSettingsHasThemAndPassesTheStrictChecks) {
  const std::string path = ::testing::TempDir() + "/settings_scene.toml";
  {
    FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs(kScene.c_str(), f);
    std::fclose(f);
  }
  const Scene s = parse_scene_file(path, {parse_scene_setting("materials.soft.E=4500"),
                                          parse_scene_setting("+solver.dt=1e-4")});
  EXPECT_DOUBLE_EQ(s.materials.at("soft").youngs_modulus_pa, 4500);
  EXPECT_DOUBLE_EQ(s.solver.dt_s.value_or(0), 1e-4);
  EXPECT_NE(s.source_text.find("E = 4500"), std::string::npos);  // result.h5 keeps the scene as run
  EXPECT_EQ(s.source_path, path);
  EXPECT_THROW(parse_scene_file(path, {parse_scene_setting("materials.soft.E=-1")}), Error);  // strict range check
  EXPECT_THROW(parse_scene_file(path, {parse_scene_setting("materials.soft.Ee=1")}), Error);  // no such key
  std::remove(path.c_str());
}

TEST(SceneValues, ReadsStringValues) {
  EXPECT_EQ(scene_string_value(kScene, "s", "track.1.name"), "top");
  EXPECT_EQ(scene_string_value(kScene, "s", "model.image"), "");
}

}  // namespace
}  // namespace vb
