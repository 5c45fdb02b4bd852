// Positioning metrics from a prescribed final state (no simulation): tumour centroid, target,
// chest-wall distances and comfort proxies follow their definitions.
#include <gtest/gtest.h>

#include "engine/error.hpp"
#include "engine/lattice/voxelise.hpp"
#include "engine/study/positioning_metrics.hpp"
#include "engine/study/reproducibility.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

struct Case {
  Scene scene;
  test::Model model;
};

/// A 20 mm cube of "soft" with a 4 mm "tumour" cube at (8..12, 8..12, 12..16) mm, and a chest-wall
/// sphere (centre 60 mm below the cube, radius 61 mm) holding its bottom.
Case make_case() {
  Case c;
  c.scene = test::box_scene(10, 10, 10, 0.002);
  ShapeSpec tumour = c.scene.model.shapes[0];
  tumour.min_m = Vec3(0.008, 0.008, 0.012);
  tumour.max_m = Vec3(0.012, 0.012, 0.016);
  tumour.label = "tumour";
  c.scene.model.shapes.push_back(tumour);
  c.scene.materials["tumour"] = test::material("tumour", 20000, 1050);
  AnchorSpec wall;
  wall.name = "chest";
  wall.kind = AnchorSpec::Kind::Sphere;
  wall.center_m = Vec3(0.01, 0.01, -0.06);
  wall.radius_m = 0.0615;
  c.scene.anchors.push_back(wall);
  c.scene.positioning.target_m = Vec3(0.01, 0.01, 0.02);
  c.model = test::make_model(c.scene);
  return c;
}

FinalState translated(const Lattice& lattice, const Vec3& d) {
  FinalState st;
  const std::size_t n = lattice.element_count();
  for (std::size_t e = 0; e < n; ++e)
    for (int k = 0; k < 3; ++k) {
      st.displacement_m.push_back(d[k]);
      st.position_m.push_back(lattice.rest_position(e)[k] + d[k]);
    }
  st.equivalent_strain.assign(n, 0.0);
  st.von_mises_stress_pa.assign(n, 0.0);
  for (std::size_t e = 0; e < n; ++e) st.equivalent_strain[e] = double(e % 100) / 1000;  // 0 … 0.099
  st.von_mises_stress_pa[7] = 1234;
  return st;
}

TEST(PositioningMetrics, TumourCentroidTargetAndChestWall) {
  const Case c = make_case();
  const Vec3 d(0.001, -0.002, 0.003);
  RunSummary summary;
  summary.volume_change = -0.01;
  const PositioningMetrics m =
      compute_positioning_metrics(c.scene, c.model.lattice, c.model.elements, summary, translated(c.model.lattice, d));
  ASSERT_TRUE(m.tumour.has_value());
  EXPECT_EQ(m.tumour->tissue, "tumour");  // found by its default name
  EXPECT_EQ(m.tumour->elements, 8u);
  EXPECT_NEAR((m.tumour->rest_centroid_m - Vec3(0.01, 0.01, 0.014)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((m.tumour->displacement_m() - d).norm(), 0.0, 1e-12);
  EXPECT_NEAR(m.tumour->rest_target_distance_m, 0.006, 1e-12);
  EXPECT_NEAR(m.tumour->final_target_distance_m, (Vec3(0.011, 0.008, 0.017) - Vec3(0.01, 0.01, 0.02)).norm(), 1e-12);
  ASSERT_TRUE(m.chest_wall.has_value());  // the only sphere anchor
  EXPECT_EQ(m.chest_wall->anchor, "chest");
  const Vec3 centre(0.01, 0.01, -0.06);
  EXPECT_NEAR(*m.chest_wall->tumour_rest_m, 0.074 - 0.0615, 1e-12);
  EXPECT_NEAR(*m.chest_wall->tumour_final_m, (Vec3(0.011, 0.008, 0.017) - centre).norm() - 0.0615, 1e-12);
  // free elements only: every one lies outside the sphere, and the farthest is a top corner
  EXPECT_GT(m.chest_wall->mean_rest_m, 0.0);
  EXPECT_NEAR(m.chest_wall->max_rest_m, (Vec3(0.001, 0.001, 0.019) - centre).norm() - 0.0615, 1e-12);
  EXPECT_DOUBLE_EQ(m.volume_change, -0.01);
  EXPECT_DOUBLE_EQ(m.comfort.peak_equivalent_strain, 0.099);
  EXPECT_DOUBLE_EQ(m.comfort.p95_equivalent_strain, 0.094);  // nearest rank over 10 × (0 … 0.099)
  EXPECT_DOUBLE_EQ(m.comfort.peak_von_mises_pa, 1234);
}

TEST(PositioningMetrics, HalfspaceChestWallAndNamedTissue) {
  Case c = make_case();
  c.scene.anchors.push_back(test::halfspace_anchor("base", Vec3(0, 0, 0.002), Vec3(0, 0, -1)));
  c.scene.positioning.chest_wall = "base";
  c.scene.positioning.tumour_tissue = "soft";
  c.model = test::make_model(c.scene);
  const PositioningMetrics m = compute_positioning_metrics(c.scene, c.model.lattice, c.model.elements, RunSummary{},
                                                           translated(c.model.lattice, Vec3(0, 0, 0.001)));
  EXPECT_EQ(m.tumour->tissue, "soft");
  EXPECT_EQ(m.chest_wall->anchor, "base");
  EXPECT_NEAR(m.chest_wall->max_rest_m, 0.017, 1e-12);  // top layer (z = 19 mm) over the plane z = 2 mm
  EXPECT_NEAR(m.chest_wall->max_final_m - m.chest_wall->max_rest_m, 0.001, 1e-12);
  EXPECT_NEAR(m.chest_wall->mean_final_m - m.chest_wall->mean_rest_m, 0.001, 1e-12);
}

TEST(PositioningMetrics, MissingTumourTissueIsAnErrorOnlyWhenNamed) {
  Case c = make_case();
  c.scene.positioning.tumour_tissue = "idc";
  const FinalState st = translated(c.model.lattice, Vec3::Zero());
  EXPECT_THROW(compute_positioning_metrics(c.scene, c.model.lattice, c.model.elements, RunSummary{}, st), Error);
  c.scene.positioning.tumour_tissue.clear();
  c.scene.model.shapes.pop_back();  // no tumour tissue, none named: no tumour metrics
  c.model = test::make_model(c.scene);
  const PositioningMetrics m = compute_positioning_metrics(c.scene, c.model.lattice, c.model.elements, RunSummary{},
                                                           translated(c.model.lattice, Vec3::Zero()));
  EXPECT_FALSE(m.tumour.has_value());
  ASSERT_TRUE(m.chest_wall.has_value());
  EXPECT_FALSE(m.chest_wall->tumour_rest_m.has_value());
}

}  // namespace
}  // namespace vb

// ---- reproducibility (engine/study/reproducibility.cpp) ---------------------------------------

namespace vb {
namespace {

TEST(Reproducibility, AnglesAreSeededUniformWithinTheBound) {
  ReproducibilitySpec spec;
  spec.perturbations = 400;
  spec.max_angle_deg = 1.5;
  spec.seed = 3;
  const std::vector<Vec3> a = perturbation_angles_deg(spec), again = perturbation_angles_deg(spec);
  ASSERT_EQ(a.size(), 400u);
  EXPECT_EQ(a, again);  // the same seed, the same study
  spec.seed = 4;
  EXPECT_NE(a, perturbation_angles_deg(spec));
  Vec3 mean = Vec3::Zero(), mean_sq = Vec3::Zero();
  for (const Vec3& x : a) {
    EXPECT_LE(x.cwiseAbs().maxCoeff(), 1.5);
    mean += x / 400.0;
    mean_sq += x.cwiseProduct(x) / 400.0;
  }
  // uniform on [−θ, θ]: mean 0, variance θ²/3 = 0.75 (sampling error ~0.04 and ~0.04 here)
  EXPECT_LT(mean.cwiseAbs().maxCoeff(), 0.2);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean_sq[c], 0.75, 0.15);
}

TEST(Reproducibility, SpreadIsTheRmsAndLargestDistanceFromTheMean) {
  const std::vector<Vec3> p = {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 2, 0), Vec3(0, -2, 0)};
  const TumourSpread s = tumour_spread(p);
  EXPECT_EQ(s.runs, 4);
  EXPECT_LT(s.mean_m.norm(), 1e-15);
  EXPECT_NEAR(s.std_axis_m.x(), std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(s.std_axis_m.y(), std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(s.std_m, std::sqrt(2.5), 1e-15);  // mean of 1, 1, 4, 4
  EXPECT_DOUBLE_EQ(s.max_m, 2.0);
  EXPECT_EQ(tumour_spread({}).runs, 0);
}

// A posture run that stopped at max_steps is kept in the spread and named in a warning.
TEST(Reproducibility, RunsThatStoppedBeforeEquilibriumAreNamed) {
  ReproducibilityResult r;
  for (int k = 1; k <= 3; ++k)
    for (const bool device : {true, false}) {
      PerturbedRun run;
      run.index = k;
      run.device = device;
      run.converged = true;
      r.runs.push_back(run);
    }
  EXPECT_FALSE(unsettled_runs_warning(r)) << "every run settled";
  r.runs[2].converged = false;  // posture 2 with the device
  r.runs[5].converged = false;  // posture 3 without it
  const auto w = unsettled_runs_warning(r);
  ASSERT_TRUE(w.has_value());
  EXPECT_EQ(w->rfind("2 of 6 perturbed runs stopped before equilibrium", 0), 0u) << *w;
  EXPECT_NE(w->find("posture 2 with the device, posture 3 without it"), std::string::npos) << *w;
  EXPECT_NE(w->find("stop.max_steps"), std::string::npos) << *w;
}

}  // namespace
}  // namespace vb
