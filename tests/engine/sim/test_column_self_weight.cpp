// A slender block under self-weight with a held base against the 1-D column solution
// u_top = ρ g L² / (2E): linear springs at two spacings, within 10% and closer at the finer
// spacing; then each law with its own masses and with the other body's (docs/PHYSICS.md, "Mass").
#include <gtest/gtest.h>

#include <string>

#include "engine/lattice/dual_cells.hpp"
#include "engine/sim/element_mass.hpp"
#include "engine/sim/run.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

/// Relative error (signed) of the top displacement for a 4 cm × 4 cm × 10 cm column at spacing
/// h. Law "linear" (springs), or a hyperelastic law at ν = 0 (no lateral contraction: the column
/// is exactly 1-D). `swap_mass` gives the other body's masses (a test-only change: hyperelastic
/// elements a whole voxel, spring elements their dual-volume share).
double column_error(double h, const std::string& law = "linear", bool swap_mass = false) {
  // E = 1 MPa keeps the strain small (ρgL/E ≈ 0.1%), the regime of the closed form.
  const double width = 0.04, length = 0.10, E = 1e6, rho = 1000, g = 9.81;
  const int nxy = int(std::lround(width / h)), nz = int(std::lround(length / h));
  Scene s = test::box_scene(nxy, nxy, nz + 1, h, E);  // one extra layer below z = 0 is the held base
  s.model.shapes[0].min_m.z() = -h;
  s.model.shapes[0].max_m.z() = length;
  s.materials["soft"].law = law;
  if (law != "linear") s.materials["soft"].poisson_ratio = 0;
  s.anchors.push_back(test::halfspace_anchor("base", Vec3::Zero(), Vec3(0, 0, -1)));
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -g);
  s.solver.damping_per_s = 1000;  // about critical for the first axial mode (ω₁ = π/2L·√(E/ρ) ≈ 500/s)
  s.solver.dashpot_ratio = 0.1;
  s.stop.equilibrium = 1e-6;
  s.stop.max_steps = 100000;
  s.solver.precision = Precision::Double;
  auto m = test::make_model(s);
  if (swap_mass)
    for (std::size_t e = 0; e < m.lattice.element_count(); ++e) {
      const double w = law == "linear" ? dual_volume_fraction(m.lattice.neighbours(e))
                                       : 1 / mass_volume_fraction(m.lattice, m.elements, e);
      m.elements.mass_kg[e] *= w;
      if (m.elements.inverse_mass[e] != 0) m.elements.inverse_mass[e] /= w;
    }
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  const RunOutput out = run_simulation(s, m.lattice, m.elements, sim);
  EXPECT_TRUE(out.summary.converged) << law << ", h = " << h << " stopped at " << out.summary.stop_reason;
  // Mean z displacement of the top layer against the closed form at the top of the column.
  double top = 0;
  int count = 0;
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e)
    if (m.lattice.rest_position(e).z() > length - h) top += out.state.displacement_m[3 * e + 2], ++count;
  top /= count;
  const double exact = -rho * g * length * length / (2 * E);
  return top / exact - 1;
}

TEST(ColumnSelfWeight, MatchesOneDimensionalSolutionAndConvergesWithSpacing) {
  const double coarse = std::abs(column_error(0.005));   //  8 ×  8 × 21 elements
  const double fine = std::abs(column_error(0.0025));   // 16 × 16 × 41 elements
  RecordProperty("error_h5mm", std::to_string(coarse));
  RecordProperty("error_h2_5mm", std::to_string(fine));
  EXPECT_LT(coarse, 0.10) << "coarse error " << coarse;
  EXPECT_LT(fine, 0.10) << "fine error " << fine;
  EXPECT_LT(fine, coarse) << "error must shrink when the spacing is halved";
}

// Hyperelastic tissue models the hull of the centres, springs the voxels: each law's own masses
// (hull for hyperelastic, voxels for springs) must land closer to the closed form than the other
// body's. Both bodies are `length` long between clamp and top: the hull from the held centres to
// the top centres, the springs' voxels from the held layer's top face to the top voxel face.
TEST(ColumnSelfWeight, EachLawsOwnMassMatchesTheClosedFormBetter) {
  const double h = 0.005;
  const double nh = column_error(h, "neo-hookean"), nh_voxel = column_error(h, "neo-hookean", true);
  const double lin = column_error(h), lin_hull = column_error(h, "linear", true);
  std::printf("column sag error at h = 5 mm: neo-Hookean (ν 0) %+.2f%% (with voxel masses %+.2f%%); "
              "linear springs %+.2f%% (with hull masses %+.2f%%)\n",
              100 * nh, 100 * nh_voxel, 100 * lin, 100 * lin_hull);
  RecordProperty("neo_hookean_error", std::to_string(nh));
  RecordProperty("neo_hookean_voxel_mass_error", std::to_string(nh_voxel));
  RecordProperty("linear_error", std::to_string(lin));
  RecordProperty("linear_hull_mass_error", std::to_string(lin_hull));
  EXPECT_LT(std::abs(nh), 0.02) << "hyperelastic body and mass are the hull";
  EXPECT_GT(nh_voxel, 0.25) << "voxel masses overload the hull by (8/7)² × 21/20.5 ≈ 1.34";
  EXPECT_LT(std::abs(lin), std::abs(lin_hull)) << "springs model the voxels: their mass is the voxels'";
}

}  // namespace
}  // namespace vb
