// Element masses (docs/PHYSICS.md, "Mass"): hyperelastic tissue carries the mass of the hull of
// the element centres (each element its complete dual-cell octants, ⅛ of a voxel each), spring
// tissue the mass of its voxels; mixed cells give each corner its own tissue's share; elements
// with no complete dual cell get a floor and are counted. (Which mass matches each law's body:
// ColumnSelfWeight.EachLawsOwnMassMatchesTheClosedFormBetter.)
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "engine/sim/element_mass.hpp"
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

}  // namespace
}  // namespace vb
