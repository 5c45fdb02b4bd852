// The palpation paper's truth cube (000_cec263896ad2aa44.txt): an 8 cm cube of adipose tissue
// (E = 500 Pa) with a spherical tumour (E = 10 kPa), probed by a line of presses across its top.
// The force profile's excess over the tumour-free cube is a bump above the tumour whose width
// (FWHM) must grow with the tumour's diameter; the displacement at a given force is smaller above
// the tumour. A coarse (4 mm) lattice keeps this at CI size; scripts/palpation_sweep.py runs the
// paper's ranges at 2 mm (docs/VALIDATION.md, "Probing: palpation and indenters").
#include <gtest/gtest.h>

#include "engine/probe/force_profile.hpp"
#include "tests/engine/probe/probe_fixtures.hpp"

namespace vb {
namespace {

constexpr double kH = 0.004, kSide = 0.08;
const Vec3 kTumourCentre(0.042, 0.042, 0.058);  // on an element column, 2.2 cm below the top

Scene palpation_cube(double tumour_diameter_m) {
  Scene s = test::probe_block(20, 20, 20, kH, 500);
  s.model.shapes[0].label = "adipose";
  s.materials.clear();
  s.materials["adipose"] = test::material("adipose", 500);
  if (tumour_diameter_m > 0) {
    ShapeSpec t;
    t.kind = ShapeSpec::Kind::Sphere;
    t.center_m = kTumourCentre;
    t.radius_m = 0.5 * tumour_diameter_m;
    t.label = "tumour";
    s.model.shapes.push_back(t);
    s.materials["tumour"] = test::material("tumour", 10000);
  }
  IndenterSpec finger;
  finger.kind = IndenterSpec::Kind::Sphere;
  finger.radius_m = 0.008;
  s.indenters.push_back(finger);
  s.probe = test::press_at(0.010, kTumourCentre.y(), 0.004, 2);
  s.probe.to_m = Vec3(0.074, kTumourCentre.y(), 1.0);
  s.probe.presses = 9;  // every 8 mm, over every other element column from x = 10 to 74 mm
  s.stop.equilibrium = 1e-5;
  s.probe.at_force_n = {0.004};
  return s;
}

struct Profile {
  std::vector<double> x, force, depth_at_force;
};

Profile profile(const ProbeResult& r) {
  Profile p;
  for (const PressResult& press : r.presses) {
    p.x.push_back(press.start_m.x());
    p.force.push_back(press.peak_force_n);
    p.depth_at_force.push_back(press.depth_at_force_m.at(0));
  }
  return p;
}

TEST(Probing, PalpationProfileWidthGrowsWithTumourDiameter) {
  const Profile base = profile(test::run_probe(palpation_cube(0)));
  std::vector<double> widths;
  for (double diameter : {0.016, 0.032}) {
    const ProbeResult r = test::run_probe(palpation_cube(diameter));
    EXPECT_EQ(r.unconverged_increments, 0);
    const Profile p = profile(r);
    std::vector<double> excess(p.force.size());
    for (std::size_t k = 0; k < excess.size(); ++k) excess[k] = p.force[k] - base.force[k];
    const std::size_t peak = std::size_t(std::max_element(excess.begin(), excess.end()) - excess.begin());
    widths.push_back(full_width_half_maximum(p.x, excess));
    std::printf("D %.0f mm: baseline %.4g N, peak excess %.4g N (%.1f%%) at x = %.0f mm, FWHM %.1f mm; depth at 4 mN "
                "%.3f mm (baseline %.3f mm)\n",
                1e3 * diameter, base.force[peak], excess[peak], 100 * excess[peak] / base.force[peak], 1e3 * p.x[peak],
                1e3 * widths.back(), 1e3 * p.depth_at_force[peak], 1e3 * base.depth_at_force[peak]);
    // The bump sits over the tumour, and the tissue there is stiffer than without it.
    EXPECT_NEAR(p.x[peak], kTumourCentre.x(), 1.5 * kH);
    EXPECT_GT(excess[peak], 0.01 * base.force[peak]);
    EXPECT_LT(p.depth_at_force[peak], base.depth_at_force[peak]);
  }
  EXPECT_GT(widths[1], widths[0]) << "a larger tumour gives a wider force profile";
}

}  // namespace
}  // namespace vb
