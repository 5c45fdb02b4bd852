// A slender block under self-weight with a held base against the 1-D column solution
// u_top = ρ g L² / (2E), at two spacings: within 10%, and closer at the finer spacing.
#include <gtest/gtest.h>

#include "engine/sim/run.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

/// Relative error of the top displacement for a 4 cm × 4 cm × 10 cm column at spacing h.
double column_error(double h) {
  // E = 1 MPa keeps the strain small (ρgL/E ≈ 0.1%), the regime of the closed form.
  const double width = 0.04, length = 0.10, E = 1e6, rho = 1000, g = 9.81;
  const int nxy = int(std::lround(width / h)), nz = int(std::lround(length / h));
  Scene s = test::box_scene(nxy, nxy, nz + 1, h, E);  // one extra layer below z = 0 is the held base
  s.model.shapes[0].min_m.z() = -h;
  s.model.shapes[0].max_m.z() = length;
  s.anchors.push_back(test::halfspace_anchor("base", Vec3::Zero(), Vec3(0, 0, -1)));
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -g);
  s.solver.damping_per_s = 1000;  // about critical for the first axial mode (ω₁ = π/2L·√(E/ρ) ≈ 500/s)
  s.solver.dashpot_ratio = 0.1;
  s.stop.equilibrium = 1e-6;
  s.stop.max_steps = 100000;
  s.solver.precision = Precision::Double;
  const auto m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  const RunOutput out = run_simulation(s, m.lattice, m.elements, sim);
  EXPECT_TRUE(out.summary.converged) << "h = " << h << " stopped at " << out.summary.stop_reason;
  // Mean z displacement of the top layer against the closed form at the top of the column.
  double top = 0;
  int count = 0;
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e)
    if (m.lattice.rest_position(e).z() > length - h) top += out.state.displacement_m[3 * e + 2], ++count;
  top /= count;
  const double exact = -rho * g * length * length / (2 * E);
  return std::abs(top - exact) / std::abs(exact);
}

TEST(ColumnSelfWeight, MatchesOneDimensionalSolutionAndConvergesWithSpacing) {
  const double coarse = column_error(0.005);   //  8 ×  8 × 21 elements
  const double fine = column_error(0.0025);   // 16 × 16 × 41 elements
  RecordProperty("error_h5mm", std::to_string(coarse));
  RecordProperty("error_h2_5mm", std::to_string(fine));
  EXPECT_LT(coarse, 0.10) << "coarse error " << coarse;
  EXPECT_LT(fine, 0.10) << "fine error " << fine;
  EXPECT_LT(fine, coarse) << "error must shrink when the spacing is halved";
}

}  // namespace
}  // namespace vb
