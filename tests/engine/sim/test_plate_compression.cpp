// Uniaxial compression of a hyperelastic cube between two frictionless plates (a fixed one below,
// a moving one above) to 10%, 30% and 50% strain: the top plate's force over the body's
// undeformed area against the incompressible Ogden closed form (liver paper eq. 3). The plates
// touch the outer layers' centres, which bound the elastic body (docs/PHYSICS.md, "Element
// volume"), so the cube is (n − 1)·h on a side and its stretch is the plates' gap over (n − 1)·h.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "engine/material/hyperelastic.hpp"
#include "engine/sim/run.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

struct Level {
  const char* law;
  double stretch;
};

class PlateCompression : public ::testing::TestWithParam<Level> {};

TEST_P(PlateCompression, NominalStressMatchesClosedForm) {
  const Level c = GetParam();
  const int n = 10;
  const double h = 0.002, span = (n - 1) * h;  // plates touch the outer layers' centres
  Scene s = test::box_scene(n, n, n, h);
  s.materials["soft"] = test::validation_material(c.law, 0.495);
  s.indenters = test::plate_pair(n, h, c.stretch);
  // Hold the cube's centre column in x and y only through symmetry: the plates are frictionless, so
  // nothing else stops a drift; a drift does not change the forces.
  s.solver.precision = Precision::Double;
  s.solver.damping_per_s = 300;  // about critical for the first mode
  s.solver.dashpot_ratio = 0.1;
  s.stop.equilibrium = 1e-8;
  s.stop.max_steps = 100000;
  const test::Model m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  const RunOutput out = run_simulation(s, m.lattice, m.elements, sim);
  ASSERT_TRUE(out.summary.converged) << out.summary.stop_reason;
  const double force = out.summary.indenters[1].reaction_force_n.z();  // tissue pushes the top plate up
  const double nominal = force / (span * span);
  // The interior must follow the plates: a check that no hourglass pattern takes up the strain.
  const double interior_stretch = test::interior_stretch(m.lattice, out.state.position_m, n, h);
  EXPECT_NEAR(interior_stretch, c.stretch, 0.01 * (1 - c.stretch)) << "the interior follows the plates";
  const double exact = -uniaxial_nominal_stress(law_of(s.materials.at("soft")), c.stretch);
  RecordProperty(std::string(c.law) + "_" + std::to_string(c.stretch), std::to_string(nominal / exact));
  EXPECT_NEAR(nominal / exact, 1.0, 0.03) << c.law << " λ = " << c.stretch << ": " << nominal << " vs " << exact
                                         << " Pa after " << out.summary.steps << " steps";
}

INSTANTIATE_TEST_SUITE_P(Levels, PlateCompression,
                         ::testing::Values(Level{"neo_hookean", 0.9}, Level{"neo_hookean", 0.7},
                                           Level{"neo_hookean", 0.5}, Level{"ogden", 0.9}, Level{"ogden", 0.7},
                                           Level{"ogden", 0.5}),
                         [](const auto& info) {  // e.g. ogden_stretch_70
                           return std::string(info.param.law) + "_stretch_" +
                                  std::to_string(int(std::lround(100 * info.param.stretch)));
                         });

}  // namespace
}  // namespace vb
