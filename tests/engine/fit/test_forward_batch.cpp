// Batched forward solves (docs/FIT.md, "Batched solves"): K copies of a model in one simulator
// give each copy's equilibrium as its own solve would, hyperelastic copies included, without
// needing more relaxation steps than the slowest copy alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "engine/error.hpp"
#include "engine/fit/forward_model.hpp"
#include "engine/lattice/tiled_lattice.hpp"
#include "tests/engine/fit/fit_fixtures.hpp"

namespace vb {
namespace {

TEST(TiledLattice, CopiesNeverNeighbourEachOther) {
  const Lattice one = build_lattice(voxelise_shapes(test::box_scene(3, 4, 2, 0.002)));
  const std::size_t n = one.element_count();
  const Lattice three = tile_lattice(one, 3, 2);
  ASSERT_EQ(three.element_count(), 3 * n);
  EXPECT_EQ(three.dims[2], 3 * 2 + 2);  // two empty separating layers
  EXPECT_EQ(three.connection_count, 3 * one.connection_count);
  std::size_t links = 0;
  for (std::size_t e = 0; e < three.element_count(); ++e) {
    for (std::int32_t f : three.neighbours(e)) {
      if (f < 0) continue;
      EXPECT_EQ(std::size_t(f) / n, e / n) << "element " << e << " neighbours " << f;
      ++links;
    }
    EXPECT_EQ(three.tissue_of_element[e], one.tissue_of_element[e % n] + 2 * (e / n));
    EXPECT_EQ(three.voxel_ijk(e)[0], one.voxel_ijk(e % n)[0]);
  }
  EXPECT_EQ(links, 2 * three.connection_count);
  EXPECT_EQ(three.tissue_names[2], one.tissue_names[0] + "@1");
  EXPECT_THROW(tile_lattice(one, 200, 2), Error);  // 400 tissue ids
}

struct BatchCase {
  std::string name;
  MaterialSpec tumour;
};

class ForwardBatch : public ::testing::TestWithParam<BatchCase> {};

TEST_P(ForwardBatch, EqualsSequentialSolvesToTheEquilibriumTolerance) {
  const Scene s = test::fit_box_scene(test::material("soft", 3000), GetParam().tumour);
  const Lattice lattice = build_lattice(voxelise_shapes(s));
  FitSpec f = test::fit_box_spec();
  f.batch = 8;  // auto would solve one at a time on a CPU device
  // A tight tolerance, so that what separates batch from alone is far below a Jacobian column's
  // 5% effect: at the default 1e-7 both are equilibria only to ~1e-7 m here (0.4% of a column).
  f.equilibrium = 1e-10;
  const FitRegions regions = make_fit_regions(f, s, lattice);
  ASSERT_EQ(regions.size(), 2u);
  const ForwardModel model(s, lattice, regions, f, test::cl_context());
  EXPECT_EQ(model.batch_size(), 8u);
  const std::vector<double> E0 = {3000, 15000};
  const ForwardSolution base = model.solve(E0);
  // The Jacobian's perturbations (±5% in ln E), and a larger step as a trial would take.
  const std::vector<std::vector<double>> moduli = {
      {3000 * std::exp(0.05), 15000}, {3000, 15000 * std::exp(0.05)}, {3000, 15000 * std::exp(-0.05)}, {2500, 20000}};
  std::vector<ForwardSolution> alone;
  std::int64_t slowest = 0;
  for (const auto& E : moduli) {
    alone.push_back(model.solve(E, &base));
    slowest = std::max(slowest, alone.back().steps);
  }
  const std::vector<ForwardSolution> batch = model.solve_batch(moduli, &base);
  ASSERT_EQ(batch.size(), moduli.size());
  const std::vector<double> d0 = base.change_m();
  double largest = 0;
  for (double x : d0) largest = std::max(largest, std::abs(x));
  ASSERT_GT(largest, 1e-4);  // the posture change moves the box by some 0.1 mm at least
  for (std::size_t k = 0; k < moduli.size(); ++k) {
    const std::vector<double> a = alone[k].change_m(), b = batch[k].change_m();
    ASSERT_EQ(a.size(), b.size());
    double diff = 0, column = 0;  // batch vs alone; and the perturbation's effect (a Jacobian column)
    for (std::size_t i = 0; i < a.size(); ++i) {
      diff = std::max(diff, std::abs(a[i] - b[i]));
      column = std::max(column, std::abs(a[i] - d0[i]));
    }
    // Both are equilibria to the tolerance (the difference shrinks with it: ~1e-7 m at 1e-7,
    // ~1e-10 m at 1e-10); it must lie far below the effect of a 5% modulus step.
    EXPECT_LT(diff, 1e-7 * largest) << GetParam().name << " set " << k;
    EXPECT_LT(diff, 1e-4 * column) << GetParam().name << " set " << k;
  }
  // The shared damping does not slow the copies (forward_batch.cpp): no more steps than the
  // slowest copy alone, within a few checks.
  EXPECT_LE(batch.front().steps, slowest + 5 * s.solver.check_every)
      << GetParam().name << ": batch " << batch.front().steps << " steps, slowest alone " << slowest;
  std::cout << GetParam().name << ": batch of " << moduli.size() << " in " << batch.front().steps
            << " steps; alone " << alone[0].steps << ", " << alone[1].steps << ", " << alone[2].steps << ", "
            << alone[3].steps << "\n";
}

MaterialSpec ogden_tumour() {
  MaterialSpec m = test::material("tumour", 15000);
  m.law = "ogden";
  m.ogden_mu_pa = {6000, -1500};  // μ₀ = 13.5 kPa; the forward model scales it to each E asked for
  m.ogden_alpha = {4, -2};
  m.poisson_ratio = 0.45;
  return m;
}

INSTANTIATE_TEST_SUITE_P(Laws, ForwardBatch,
                         ::testing::Values(BatchCase{"linear", test::material("tumour", 15000)},
                                           BatchCase{"ogden", ogden_tumour()}),
                         [](const auto& info) { return info.param.name; });

TEST(ForwardBatchSize, AutoIsOneAndOneWithAVolumeConstraint) {
  Scene s = test::fit_box_scene(test::material("soft", 3000), test::material("tumour", 15000));
  const Lattice lattice = build_lattice(voxelise_shapes(s));
  FitSpec f = test::fit_box_spec();
  const FitRegions regions = make_fit_regions(f, s, lattice);
  const ClContext& cl = test::cl_context();
  const std::size_t automatic = ForwardModel(s, lattice, regions, f, cl).batch_size();
  // auto solves one at a time on every device: batches lost per Jacobian on PoCL and on an H200
  // (docs/FIT.md, "Batched solves")
  EXPECT_EQ(automatic, 1u);
  f.batch = 200;
  EXPECT_EQ(ForwardModel(s, lattice, regions, f, cl).batch_size(), 200u);  // springs: no tissue-id limit
  s.volume.preserve = true;  // one constraint per simulator: copies would share it
  f.batch = 8;
  EXPECT_EQ(ForwardModel(s, lattice, regions, f, cl).batch_size(), 1u);
}

}  // namespace
}  // namespace vb
