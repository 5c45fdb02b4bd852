// Element masses (docs/PHYSICS.md, "Mass"): hyperelastic tissue carries the mass of the hull of
// the element centres (each element its complete dual-cell octants, ⅛ of a voxel each), spring
// tissue the mass of its voxels; mixed cells give each corner its own tissue's share; elements
// with no complete dual cell get a floor and are counted. Then a column under self-weight against
// the 1-D closed form u_top = ρgL²/(2E), each law with its own masses and with the other law's,
// to show which mass matches each law's body.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "engine/lattice/dual_cells.hpp"
#include "engine/sim/element_mass.hpp"
#include "engine/sim/run.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

constexpr double kH = 0.004;
constexpr double kRho = 1000;

double total_mass(const ElementArrays& el) {
  double m = 0;
  for (const double x : el.mass_kg) m += x;
  return m;
}

TEST(LumpedMass, HyperelasticCubeCarriesTheHullOfItsCentresAndSpringsTheirVoxels) {
  const int n = 5;
  Scene s = test::box_scene(n, n, n, kH);
  const double voxel = kRho * kH * kH * kH;
  const test::Model springs = test::make_model(s);
  EXPECT_NEAR(total_mass(springs.elements), n * n * n * voxel, 1e-12 * n * n * n * voxel);
  for (std::size_t e = 0; e < springs.lattice.element_count(); ++e)
    EXPECT_EQ(mass_volume_fraction(springs.lattice, springs.elements, e), 1.0);

  s.materials["soft"].law = "neo-hookean";
  s.materials["soft"].poisson_ratio = 0.45;
  const test::Model hyper = test::make_model(s);
  const double hull = (n - 1) * (n - 1) * (n - 1) * voxel;
  EXPECT_NEAR(total_mass(hyper.elements), hull, 1e-12 * hull);
  const TissueMass t = tissue_masses(s, hyper.lattice, hyper.elements).at(0);
  EXPECT_TRUE(t.hull_body);
  EXPECT_NEAR(t.model_kg, hull, 1e-12 * hull);
  EXPECT_NEAR(t.hull_kg, hull, 1e-12 * hull);
  EXPECT_NEAR(t.voxel_kg, n * n * n * voxel, 1e-9 * voxel);
  EXPECT_EQ(t.floored, 0u);
  // Interior 1, face ½, edge ¼, corner ⅛: ½ per outer index.
  for (std::size_t e = 0; e < hyper.lattice.element_count(); ++e) {
    const auto ijk = hyper.lattice.voxel_ijk(e);
    int outer = 0;
    for (const int c : ijk) outer += c == 0 || c == n - 1;
    EXPECT_EQ(mass_volume_fraction(hyper.lattice, hyper.elements, e), std::pow(0.5, outer));
    EXPECT_DOUBLE_EQ(hyper.elements.mass_kg[e], std::pow(0.5, outer) * voxel);
    EXPECT_DOUBLE_EQ(hyper.elements.inverse_mass[e], 1 / hyper.elements.mass_kg[e]);
  }
}

// A 4-voxel cube, springs (ρ 1000) below z = 2h, neo-Hookean (ρ 1500) above, the bottom layer held:
// the dual cells between the two tissues are complete, so each neo-Hookean element's share is its
// voxel cut by the hull of all centres, z from 1.5h to 3h over 3h × 3h: 13.5 h³; the springs
// keep their 32 voxels, held or not.
TEST(LumpedMass, MixedCellsGiveEachCornerItsOwnTissuesShare) {
  Scene s = test::box_scene(4, 4, 4, kH);
  ShapeSpec top = s.model.shapes[0];
  top.min_m.z() = 2 * kH;
  top.label = "hyper";
  s.model.shapes.push_back(top);
  s.materials["hyper"] = test::material("hyper", 3000, 1500);
  s.materials["hyper"].law = "neo-hookean";
  s.materials["hyper"].poisson_ratio = 0.45;
  s.anchors.push_back(test::halfspace_anchor("base", Vec3(0, 0, kH), Vec3(0, 0, -1)));
  const test::Model m = test::make_model(s);
  const double h3 = kH * kH * kH;
  EXPECT_NEAR(total_mass(m.elements), (32 * kRho + 13.5 * 1500) * h3, 1e-12);
  std::size_t held = 0;
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e) {
    const bool hyper = m.lattice.tissue_names[m.lattice.tissue_of_element[e]] == "hyper";
    if (!hyper) EXPECT_DOUBLE_EQ(m.elements.mass_kg[e], kRho * h3);
    if (m.lattice.voxel_ijk(e)[2] == 0) {
      EXPECT_EQ(m.elements.inverse_mass[e], 0.0);
      ++held;
    } else {
      EXPECT_DOUBLE_EQ(m.elements.inverse_mass[e], 1 / m.elements.mass_kg[e]);
    }
  }
  EXPECT_EQ(held, 16u);
}

// A one-voxel sheet of hyperelastic tissue has no complete dual cell: no elastic volume, and
// without a floor no mass. Each element gets ⅛ of a voxel (finite inverse mass), and the sheet is
// counted, so the app can say so.
TEST(LumpedMass, OneVoxelSheetGetsTheFloorAndIsCounted) {
  Scene s = test::box_scene(6, 6, 1, kH);
  s.materials["soft"].law = "neo-hookean";
  s.materials["soft"].poisson_ratio = 0.45;
  const test::Model m = test::make_model(s);
  const TissueMass t = tissue_masses(s, m.lattice, m.elements).at(0);
  EXPECT_EQ(t.floored, 36u);
  EXPECT_EQ(t.hull_kg, 0.0);
  EXPECT_NEAR(t.model_kg, 36 * kLeastVolumeFraction * kRho * kH * kH * kH, 1e-15);
  for (const double im : m.elements.inverse_mass) {
    EXPECT_TRUE(std::isfinite(im));
    EXPECT_GT(im, 0);
  }
}

/// Top displacement of a 4 × 4 × 10 cm column (E = 1 MPa, strain ≈ 0.1%) on a held base layer at
/// h = 5 mm, relative to ρgL²/(2E) (the geometry of ColumnSelfWeight). `swap_mass`: the other
/// body's mass (a test-only change: hyperelastic elements get a whole voxel, spring elements
/// their dual-volume share).
double column_error(const std::string& law, bool swap_mass) {
  const double h = 0.005, width = 0.04, length = 0.10, E = 1e6, g = 9.81;
  const int nxy = int(std::lround(width / h)), nz = int(std::lround(length / h));
  Scene s = test::box_scene(nxy, nxy, nz + 1, h, E);
  s.model.shapes[0].min_m.z() = -h;
  s.model.shapes[0].max_m.z() = length;
  MaterialSpec& m = s.materials["soft"];
  m.law = law;
  if (law != "linear") m.poisson_ratio = 0;  // no lateral contraction: the column is exactly 1-D
  s.anchors.push_back(test::halfspace_anchor("base", Vec3::Zero(), Vec3(0, 0, -1)));
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -g);
  s.solver.integrator = Integrator::Relaxation;
  s.solver.precision = Precision::Double;
  s.stop.equilibrium = 1e-8;
  s.stop.max_steps = 100000;
  test::Model model = test::make_model(s);
  ElementArrays& el = model.elements;
  if (swap_mass)
    for (std::size_t e = 0; e < el.mass_kg.size(); ++e) {
      const double w = law == "linear" ? dual_volume_fraction(model.lattice.neighbours(e)) : 1 / mass_volume_fraction(model.lattice, el, e);
      el.mass_kg[e] *= w;
      if (el.inverse_mass[e] != 0) el.inverse_mass[e] /= w;
    }
  Simulator sim(s, model.lattice, el, test::cl_context());
  const RunOutput out = run_simulation(s, model.lattice, el, sim);
  EXPECT_TRUE(out.summary.converged) << law << ": " << out.summary.stop_reason;
  // The top layer's centres: the hull's top face; the spring body's runs h/2 higher, but its
  // held layer is h/2 lower, so both bodies are `length` long between clamp and top.
  double top = 0;
  int count = 0;
  for (std::size_t e = 0; e < model.lattice.element_count(); ++e)
    if (model.lattice.rest_position(e).z() > length - h) top += out.state.displacement_m[3 * e + 2], ++count;
  top /= count;
  const double exact = -kRho * g * length * length / (2 * E);
  return top / exact - 1;
}

TEST(LumpedMass, EachLawsOwnMassMatchesTheColumnClosedFormBetter) {
  const double nh = column_error("neo-hookean", false), nh_voxel = column_error("neo-hookean", true);
  const double lin = column_error("linear", false), lin_hull = column_error("linear", true);
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
  EXPECT_LT(std::abs(lin), 0.10);
}

}  // namespace
}  // namespace vb
