// A press's force must not depend on the increments it is taken in (docs/PROBING.md,
// "Increments"): a flat punch placed an increment deep at once threw the elements under its rim
// onto its side wall (less force at 0.5 mm than at 0.1 mm increments), and an increment of a
// spacing let it pass through the surface layer. The probe moves to each increment along a ramp.
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/engine/probe/probe_fixtures.hpp"

namespace vb {
namespace {

constexpr double kH = 0.002;

/// A 5.5 mm-radius flat punch (its rim 0.4 mm outside the outermost elements under it) pressed
/// 2 mm into the middle of a 24 × 24 × 12 mm block (E = 3 kPa).
double punch_force(int steps) {
  Scene s = test::probe_block(12, 12, 6, kH, 3000);
  IndenterSpec punch;
  punch.kind = IndenterSpec::Kind::Cylinder;
  punch.radius_m = 0.0055;
  punch.normal = -Vec3::UnitZ();  // the press direction
  s.indenters.push_back(punch);
  s.probe = test::press_at(0.012, 0.012, kH, steps);
  const ProbeResult r = test::run_probe(s);
  const PressResult& p = r.presses.at(0);
  EXPECT_EQ(r.unconverged_increments, 0);
  EXPECT_FALSE(p.inverted);
  std::printf("punch, %d increments of %.2f mm: %.5g mN, %lld contact elements\n", steps, 1e3 * kH / steps,
              1e3 * p.peak_force_n, (long long)p.samples.back().contact_elements);
  return p.peak_force_n;
}

TEST(Probing, PunchForceDoesNotDependOnTheIncrements) {
  const double fine = punch_force(20), medium = punch_force(4), whole = punch_force(1);
  ASSERT_GT(fine, 0);
  // The ramp moves the punch through the same positions whatever the increments; what remains is
  // each increment's equilibrium tolerance.
  EXPECT_NEAR(medium / fine, 1.0, 0.01) << "0.5 mm increments";
  EXPECT_NEAR(whole / fine, 1.0, 0.01) << "one increment of a spacing";
}

}  // namespace
}  // namespace vb
