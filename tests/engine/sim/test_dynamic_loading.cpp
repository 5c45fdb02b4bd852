// Uniaxial tension and simple shear to 30%, run to equilibrium between two plates that hold the
// tissue: `slide` plates (bonded along the normal, frictionless along the surface) pull a cube,
// `stick` plates (the tissue moves with them) shear a slab. Stresses against the closed forms of
// the law (incompressible Ogden uniaxial stress, liver paper eq. 3; simple-shear σ12).
#include <gtest/gtest.h>

#include "engine/material/hyperelastic.hpp"
#include "engine/sim/run.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

RunOutput run_to_equilibrium(Scene& s, const test::Model& m) {
  s.solver.precision = Precision::Double;
  s.solver.damping_per_s = 300;  // about critical for the first mode
  s.solver.dashpot_ratio = 0.1;
  s.stop.equilibrium = 1e-8;
  s.stop.max_steps = 100000;
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  return run_simulation(s, m.lattice, m.elements, sim);
}

class Tension : public ::testing::TestWithParam<const char*> {};

TEST_P(Tension, NominalStressMatchesClosedFormAt30Percent) {
  const std::string law = GetParam();
  const int n = 8;
  const double h = 0.002, span = (n - 1) * h, stretch = 1.3, speed = 0.05;
  Scene s = test::box_scene(n, n, n, h);
  s.materials["soft"] = test::validation_material(law, 0.495);
  s.indenters = test::plate_pair(n, h, stretch, IndenterSpec::Contact::Slide, speed);
  const test::Model m = test::make_model(s);
  const RunOutput out = run_to_equilibrium(s, m);
  ASSERT_TRUE(out.summary.converged) << out.summary.stop_reason;
  EXPECT_EQ(out.summary.indenters[1].contact_elements, n * n) << "the whole top layer stays on the plate";
  // The tissue pulls the top plate back (−z); over the body's area (PHYSICS.md, "Element volume").
  const double nominal = -out.summary.indenters[1].reaction_force_n.z() / (span * span);
  const double exact = uniaxial_nominal_stress(law_of(s.materials.at("soft")), stretch);
  RecordProperty(law + "_tension_1.3", std::to_string(nominal / exact));
  EXPECT_NEAR(nominal / exact, 1.0, 0.03) << law << ": " << nominal << " vs " << exact << " Pa";
}

INSTANTIATE_TEST_SUITE_P(Laws, Tension, ::testing::Values("neo_hookean", "ogden"),
                         [](const auto& info) { return std::string(info.param); });

class SimpleShear : public ::testing::TestWithParam<const char*> {};

/// A 16 × 16 × 4 slab sheared by γ = 0.3 between stick plates. Its free side faces carry no shear,
/// so the state is simple shear only away from them: the shear stress is read from the force the
/// central 6 × 6 elements of the top layer put on the plate, over their area (h² each).
TEST_P(SimpleShear, ShearStressMatchesClosedFormAt30Percent) {
  const std::string law = GetParam();
  const int n = 16, layers = 4;
  const double h = 0.002, gap = (layers - 1) * h, gamma = 0.3, speed = 0.05;
  Scene s = test::box_scene(n, n, layers, h);
  s.materials["soft"] = test::validation_material(law, 0.49);
  s.indenters = test::plate_pair(layers, h, 1.0, IndenterSpec::Contact::Stick);  // the gap stays
  s.indenters[1].velocity_m_s = Vec3(speed, 0, 0);                                // the top slides along x
  s.indenters[1].travel_time_s = gamma * gap / speed;
  const test::Model m = test::make_model(s);
  const RunOutput out = run_to_equilibrium(s, m);
  ASSERT_TRUE(out.summary.converged) << out.summary.stop_reason;
  ASSERT_EQ(out.summary.indenters[1].contact_elements, n * n);
  // Forces on the final state: a stick plate carries each touching element's whole force.
  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  sim.upload(out.state.displacement_m, std::vector<double>(out.state.displacement_m.size(), 0.0));
  const std::vector<double> f = sim.lattice_forces();
  double shear = 0;
  int count = 0;
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e) {
    const auto ijk = m.lattice.voxel_ijk(e);
    if (ijk[2] != layers - 1 || std::min(ijk[0], n - 1 - ijk[0]) < 5 || std::min(ijk[1], n - 1 - ijk[1]) < 5) continue;
    shear -= f[3 * e];  // the tissue holds the top layer back (−x)
    ++count;
  }
  ASSERT_EQ(count, 36);
  const double sigma = shear / (count * h * h);
  const double exact = simple_shear_stress(law_of(s.materials.at("soft")), gamma);
  RecordProperty(law + "_shear_0.3", std::to_string(sigma / exact));
  EXPECT_NEAR(sigma / exact, 1.0, 0.03) << law << ": " << sigma << " vs " << exact << " Pa";
}

INSTANTIATE_TEST_SUITE_P(Laws, SimpleShear, ::testing::Values("neo_hookean", "ogden"),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace
}  // namespace vb
