// The forward model keeps one simulator across its solves (Simulator::set_materials): every solve
// must equal the same solve of a forward model built for it, to the bit.
#include <gtest/gtest.h>

#include <string>
#include <tuple>
#include <vector>

#include "engine/fit/forward_model.hpp"
#include "tests/engine/fit/fit_fixtures.hpp"

namespace vb {
namespace {

void expect_same(const ForwardSolution& a, const ForwardSolution& b) {
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_EQ(a.from_m, b.from_m);
  EXPECT_EQ(a.to_m, b.to_m);
}

class ForwardModelSolves : public ::testing::TestWithParam<FitSpec::Regions> {};

TEST_P(ForwardModelSolves, EachEqualsTheSolveOfAModelBuiltForIt) {
  const Scene s = test::fit_box_scene(test::material("soft", 3000), test::material("tumour", 15000));
  const Lattice lattice = build_lattice(voxelise_shapes(s));
  FitSpec f = test::fit_box_spec();
  f.regions = GetParam();
  const FitRegions regions = make_fit_regions(f, s, lattice);
  const auto moduli = [&](double soft, double tumour) {  // per region, by the tissue it lies in
    std::vector<double> E(regions.size(), soft);
    for (std::size_t e = 0; e < lattice.element_count(); ++e)
      if (lattice.tissue_names[lattice.tissue_of_element[e]] == "tumour" && regions.region_of_element[e] >= 0)
        E[std::size_t(regions.region_of_element[e])] = tumour;
    return E;
  };
  const ForwardModel kept(s, lattice, regions, f, test::cl_context());
  const ForwardSolution first = kept.solve(moduli(3000, 15000));
  // a warm start from another solve, a cold one, and a warm start of a Jacobian's column
  const ForwardSolution second = kept.solve(moduli(2000, 30000), &first);
  const ForwardSolution third = kept.solve(moduli(4500, 9000));
  const std::vector<ForwardSolution> column = kept.solve_batch({moduli(3000 * 1.05, 15000)}, &first);
  EXPECT_EQ(kept.jacobian_timing().simulators, 0u);  // the Jacobian's column used the kept one
  {
    const ForwardModel fresh(s, lattice, regions, f, test::cl_context());
    expect_same(second, fresh.solve(moduli(2000, 30000), &first));
  }
  {
    const ForwardModel fresh(s, lattice, regions, f, test::cl_context());
    expect_same(third, fresh.solve(moduli(4500, 9000)));
  }
  {
    const ForwardModel fresh(s, lattice, regions, f, test::cl_context());
    ASSERT_EQ(column.size(), 1u);
    expect_same(column[0], fresh.solve(moduli(3000 * 1.05, 15000), &first));
  }
  EXPECT_NE(second.to_m, third.to_m);  // the moduli moved the solution (the comparison sees them)
}

// From the unloaded reference state the fixed point's simulator and the posture's are kept too.
TEST(ForwardModelUnloadedReference, EachSolveEqualsTheSolveOfAModelBuiltForIt) {
  Scene s = test::fit_box_scene(test::material("soft", 3000), test::material("tumour", 15000));
  s.reference_state.active = true;
  s.reference_state.ct_gravity_m_s2 = Vec3(0, 9.81, 0);  // the image was taken in the `from` posture
  const Lattice lattice = build_lattice(voxelise_shapes(s));
  FitSpec f = test::fit_box_spec();
  f.from_gravity_m_s2.reset();  // the image posture is [reference_state]'s
  const FitRegions regions = make_fit_regions(f, s, lattice);
  ASSERT_EQ(regions.size(), 2u);
  const ForwardModel kept(s, lattice, regions, f, test::cl_context());
  ASSERT_TRUE(kept.unloaded_reference());
  const ForwardSolution first = kept.solve({3000, 15000});
  const ForwardSolution second = kept.solve({2000, 30000}, &first);
  const ForwardSolution third = kept.solve({4500, 9000});
  for (const auto& [E, warm, solution] : {std::tuple{std::vector<double>{2000, 30000}, &first, &second},
                                           std::tuple{std::vector<double>{4500, 9000}, (const ForwardSolution*)nullptr, &third}}) {
    const ForwardModel fresh(s, lattice, regions, f, test::cl_context());
    const ForwardSolution alone = fresh.solve(E, warm);
    expect_same(*solution, alone);
    EXPECT_EQ(solution->rest_offset_m, alone.rest_offset_m);
    EXPECT_EQ(solution->reference_solves, alone.reference_solves);
  }
  EXPECT_NE(second.to_m, third.to_m);
  // A Jacobian's column on the kept simulators: its phases and steps in jacobian_timing.
  const std::vector<ForwardSolution> column = kept.solve_batch({{3000 * 1.05, 15000}}, &first);
  const JacobianTiming& t = kept.jacobian_timing();
  ASSERT_EQ(column.size(), 1u);
  EXPECT_EQ(t.simulators, 0u);
  EXPECT_EQ(t.steps, column[0].steps);
  EXPECT_GT(column[0].reference_solves, 0);
  EXPECT_GT(t.setup_s, 0.0);
  EXPECT_GT(t.relax_s, 0.0);
  EXPECT_GT(t.readback_s, 0.0);
  const ForwardModel fresh(s, lattice, regions, f, test::cl_context());
  fresh.solve_batch({{3000 * 1.05, 15000}}, &first);
  EXPECT_EQ(fresh.jacobian_timing().simulators, 2u);  // the fixed point's and the posture's
}

// Batches keep their simulators too, one per batch size: a second Jacobian's batches equal the
// batches of a model built for them.
TEST(ForwardModelBatches, EachEqualsTheBatchOfAModelBuiltForIt) {
  const Scene s = test::fit_box_scene(test::material("soft", 3000), test::material("tumour", 15000));
  const Lattice lattice = build_lattice(voxelise_shapes(s));
  FitSpec f = test::fit_box_spec();
  f.batch = 3;  // five columns: a batch of 3 and one of 2
  const FitRegions regions = make_fit_regions(f, s, lattice);
  ASSERT_EQ(regions.size(), 2u);
  const auto columns = [](double soft, double tumour) {
    std::vector<std::vector<double>> E;
    for (double x : {1.0, 1.05, 0.95, 1.1, 0.9}) E.push_back({soft * x, tumour / x});
    return E;
  };
  const ForwardModel kept(s, lattice, regions, f, test::cl_context());
  const ForwardSolution base = kept.solve({3000, 15000});
  kept.solve_batch(columns(3000, 15000), &base);
  const std::vector<ForwardSolution> second = kept.solve_batch(columns(2500, 20000), &base);
  EXPECT_EQ(kept.jacobian_timing().simulators, 2u);  // one of 3 copies, one of 2, built once each
  const ForwardModel fresh(s, lattice, regions, f, test::cl_context());
  const std::vector<ForwardSolution> alone = fresh.solve_batch(columns(2500, 20000), &base);
  ASSERT_EQ(second.size(), alone.size());
  for (std::size_t k = 0; k < alone.size(); ++k) {
    SCOPED_TRACE("column " + std::to_string(k));
    expect_same(second[k], alone[k]);
  }
}

INSTANTIATE_TEST_SUITE_P(Regions, ForwardModelSolves,
                         ::testing::Values(FitSpec::Regions::Labels, FitSpec::Regions::Elements),
                         [](const auto& info) { return info.param == FitSpec::Regions::Labels ? "Labels" : "Elements"; });

}  // namespace
}  // namespace vb
