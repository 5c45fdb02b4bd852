// Posture changes move the tumour with gravity: a small breast (half-ellipsoid on a chest-wall
// slab held by the paper's sphere anchor) with a stiff tumour, run under several postures.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>

#include "engine/loads/posture.hpp"
#include "engine/sim/run.hpp"
#include "engine/study/positioning_metrics.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

/// Breast: half-ellipsoid towards anterior (−y), semi-axes 20 × 16 × 20 mm; chest wall: a 6 mm
/// slab behind it (y ≥ 0) held by a sphere of radius 101 mm centred 100 mm posterior; tumour:
/// a 4 mm sphere 8 mm in front of the chest wall. LPS as the phantom (docs/PHANTOM.md).
Scene breast_scene(const std::string& posture) {
  Scene s;
  s.model.spacing_m = 0.002;
  ShapeSpec slab, breast, tumour;
  slab.kind = ShapeSpec::Kind::Box;
  slab.min_m = Vec3(-0.022, 0, -0.022);
  slab.max_m = Vec3(0.022, 0.006, 0.022);
  slab.label = "muscle";
  breast.kind = ShapeSpec::Kind::HalfEllipsoid;
  breast.radii_m = Vec3(0.020, 0.016, 0.020);
  breast.axis = Vec3(0, -1, 0);
  breast.label = "adipose";
  tumour.kind = ShapeSpec::Kind::Sphere;
  tumour.center_m = Vec3(0, -0.008, 0);
  tumour.radius_m = 0.004;
  tumour.label = "tumour";
  s.model.shapes = {slab, breast, tumour};
  for (const char* tissue : {"muscle", "adipose", "tumour"})
    s.materials[tissue] = test::material(tissue, std::string(tissue) == "adipose" ? 3250 : 20000);
  AnchorSpec chest;
  chest.name = "chest";
  chest.kind = AnchorSpec::Kind::Sphere;
  chest.center_m = Vec3(0, 0.1, 0);
  chest.radius_m = 0.101;
  s.anchors.push_back(chest);
  s.gravity.active = true;
  s.gravity.posture = posture;
  s.gravity.acceleration_m_s2 = gravity_for_posture(posture);
  s.solver.damping_per_s = 30;
  s.solver.dashpot_ratio = 0.1;
  s.stop.equilibrium = 1e-4;
  s.stop.max_steps = 30000;
  return s;
}

PositioningMetrics run_posture(const std::string& posture) {
  const Scene s = breast_scene(posture);
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  const RunOutput out = run_simulation(s, m.lattice, m.elements, sim);
  EXPECT_TRUE(out.summary.converged) << posture << ": " << out.summary.stop_reason;
  return compute_positioning_metrics(s, m.lattice, m.elements, out.summary, out.state);
}

TEST(GravityFlip, TumourMovesWithGravityAndAwayFromTheChestWallWhenProne) {
  std::map<std::string, PositioningMetrics> runs;
  for (const char* posture : {"supine", "prone", "left_lateral"}) {
    const PositioningMetrics m = run_posture(posture);
    ASSERT_TRUE(m.tumour && m.chest_wall) << posture;
    const Vec3 d = m.tumour->displacement_m(), down = gravity_for_posture(posture).normalized();
    EXPECT_GT(d.norm(), 1e-4) << posture << ": the tumour barely moved";
    EXPECT_GT(d.dot(down), 0.9 * d.norm()) << posture << ": tumour moved " << d.transpose() << ", gravity along "
                                           << down.transpose();
    std::printf("%s: tumour moved %.4f %.4f %.4f mm; chest wall distance %.4f → %.4f mm, mean %.4f → %.4f mm\n", posture,
                1e3 * d.x(), 1e3 * d.y(), 1e3 * d.z(), 1e3 * *m.chest_wall->tumour_rest_m, 1e3 * *m.chest_wall->tumour_final_m,
                1e3 * m.chest_wall->mean_rest_m, 1e3 * m.chest_wall->mean_final_m);
    runs[posture] = m;
  }
  // Supine presses the tumour towards the chest wall; prone lets it hang away.
  const ChestWallMetrics &supine = *runs["supine"].chest_wall, &prone = *runs["prone"].chest_wall;
  EXPECT_LT(*supine.tumour_final_m, *supine.tumour_rest_m);
  EXPECT_GT(*prone.tumour_final_m, *prone.tumour_rest_m);
  EXPECT_GT(prone.mean_final_m, supine.mean_final_m);
  // The flip reverses the tumour's motion along y.
  EXPECT_LT(runs["supine"].tumour->displacement_m().y() * runs["prone"].tumour->displacement_m().y(), 0.0);
}

}  // namespace
}  // namespace vb
