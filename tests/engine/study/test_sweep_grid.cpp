#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "engine/error.hpp"
#include "engine/study/sweep_grid.hpp"

namespace vb {
namespace {

using Values = std::vector<std::string>;

std::string error_of(const std::string& argument) {
  try {
    parse_vary(argument);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(SweepVary, LinearRanges) {
  const SweepParameter p = parse_vary("device.torus.1.minor_radius=0.010:0.030:5");
  EXPECT_EQ(p.key, "device.torus.1.minor_radius");
  EXPECT_FALSE(p.add);
  // Rounded to 12 significant digits: 0.015, not 0.015000000000000001.
  EXPECT_EQ(p.values, (Values{"0.01", "0.015", "0.02", "0.025", "0.03"}));
  EXPECT_EQ(parse_vary("a.b=0.3:0.1:3").values, (Values{"0.3", "0.2", "0.1"}));  // descending
  EXPECT_EQ(parse_vary("a.b=-1:1:3").values, (Values{"-1", "0", "1"}));         // integers stay integers
  EXPECT_EQ(parse_vary("stop.max_steps=1000:5000:5").values, (Values{"1000", "2000", "3000", "4000", "5000"}));
  EXPECT_EQ(parse_vary("a.b=1:2:3").values, (Values{"1.0", "1.5", "2.0"}));  // a fractional step: floats
  EXPECT_EQ(parse_vary("a.b=1000:2000:4").values, (Values{"1000.0", "1333.33333333", "1666.66666667", "2000.0"}));
}

TEST(SweepVary, LogRanges) {
  EXPECT_EQ(parse_vary("materials.adipose.E=1e3:1e5:3:log").values, (Values{"1000.0", "10000.0", "100000.0"}));
  EXPECT_EQ(parse_vary("a.b=1:8:4:log").values, (Values{"1.0", "2.0", "4.0", "8.0"}));
  EXPECT_EQ(parse_vary("a.b=1:3:3:lin").values, (Values{"1", "2", "3"}));
}

TEST(SweepVary, Lists) {
  EXPECT_EQ(parse_vary("gravity.posture=prone,supine").values, (Values{"'prone'", "'supine'"}));
  EXPECT_EQ(parse_vary("solver.dt=auto,1e-4").values, (Values{"'auto'", "1e-4"}));
  EXPECT_EQ(parse_vary("gravity.vector=[0,0,-9.81], [0,-9.81,0]").values, (Values{"[0,0,-9.81]", "[0,-9.81,0]"}));
  EXPECT_EQ(parse_vary("volume.preserve=true,false").values, (Values{"true", "false"}));
  EXPECT_EQ(parse_vary("track.1.name=\"a,b\",c").values, (Values{"\"a,b\"", "'c'"}));
  EXPECT_EQ(parse_vary("a.b=7").values, (Values{"7"}));  // one value: fixed for every case
  const SweepParameter added = parse_vary("+materials.adipose.E=2000,4000");
  EXPECT_TRUE(added.add);
  EXPECT_EQ(added.key, "materials.adipose.E");
}

TEST(SweepVary, MalformedArgumentsAreErrors) {
  EXPECT_NE(error_of("materials.adipose.E").find("expected KEY=VALUES"), std::string::npos);
  EXPECT_NE(error_of("=1,2").find("the key is empty"), std::string::npos);
  EXPECT_NE(error_of("a..b=1").find("empty part"), std::string::npos);
  EXPECT_NE(error_of("a.b=1:2").find("malformed range"), std::string::npos);
  EXPECT_NE(error_of("a.b=1:2:1").find("range count"), std::string::npos);
  EXPECT_NE(error_of("a.b=1:2:2.5").find("range count"), std::string::npos);
  EXPECT_NE(error_of("a.b=1:x:3").find("finite numbers"), std::string::npos);
  EXPECT_NE(error_of("a.b=1:1:3").find("is empty"), std::string::npos);
  EXPECT_NE(error_of("a.b=-1:1:3:log").find("log range"), std::string::npos);
  EXPECT_NE(error_of("a.b=1:2:3:cubic").find("spacing"), std::string::npos);
  EXPECT_NE(error_of("a.b=1,,2").find("empty value"), std::string::npos);
  EXPECT_NE(error_of("a.b=1,2,1").find("listed twice"), std::string::npos);
  EXPECT_NE(error_of("a.b=nan").find("finite"), std::string::npos);
  EXPECT_EQ(error_of("a.b=1,2"), "");
}

TEST(SweepGrid, CartesianProductFirstParameterSlowest) {
  const SweepGrid grid({parse_vary("a.x=1,2"), parse_vary("b.y=p,q,r")});
  ASSERT_EQ(grid.size(), 6u);
  EXPECT_EQ(grid.values_of(0), (Values{"1", "'p'"}));
  EXPECT_EQ(grid.values_of(1), (Values{"1", "'q'"}));
  EXPECT_EQ(grid.values_of(2), (Values{"1", "'r'"}));
  EXPECT_EQ(grid.values_of(3), (Values{"2", "'p'"}));
  EXPECT_EQ(grid.values_of(5), (Values{"2", "'r'"}));
  EXPECT_THROW(grid.values_of(6), Error);
  const std::vector<SceneOverride> o = grid.overrides_of(4);
  ASSERT_EQ(o.size(), 2u);
  EXPECT_EQ(o[0].key, "a.x");
  EXPECT_EQ(o[0].value, "2");
  EXPECT_EQ(o[1].value, "'q'");
}

TEST(SweepGrid, NoParametersIsOneCase) {
  const SweepGrid grid({});
  EXPECT_EQ(grid.size(), 1u);
  EXPECT_TRUE(grid.overrides_of(0).empty());
}

TEST(SweepGrid, RefusesRepeatedKeysAndHugeGrids) {
  EXPECT_THROW(SweepGrid({parse_vary("a.x=1,2"), parse_vary("a.x=3")}), Error);
  EXPECT_THROW(SweepGrid({parse_vary("a.x=1:2:1000"), parse_vary("b.x=1:2:1000")}, 100000), Error);
}

}  // namespace
}  // namespace vb
