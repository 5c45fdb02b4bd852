// voxbreast fit-curve's engine (engine/curve_fit): the force-feedback paper's test model, a 6 cm
// cube of nonlinear (biphasic) springs held on every face but the top and pressed at the middle
// of the top face. A curve simulated with known parameters, fitted from a perturbed start, must
// give the parameters back with a small fit error (docs/VALIDATION.md, "Probing: fitting force curves").
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "engine/error.hpp"
#include "engine/curve_fit/curve_fit.hpp"
#include "engine/curve_fit/material_parameters.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

constexpr double kH = 0.01;  // 7 elements across: element centres span the paper's 6 cm

/// 7×7×7 elements (343, the paper's node count), biphasic springs, bottom and sides held, a
/// 4 mm sphere touching the middle element of the top face, pressing down: like the paper, it
/// moves that one element (its neighbours are 1 cm away). Beyond about 9 mm the element slips off
/// the small sphere sideways (its top is an unstable perch), so the press stops at 8 mm.
Scene paper_cube(double E, double c3, double ec) {
  Scene s = test::box_scene(7, 7, 7, kH);
  MaterialSpec& m = s.materials["soft"];
  m.law = "biphasic";
  m.youngs_modulus_pa = E;
  m.cubic = c3;
  m.critical_strain = ec;
  s.anchors.push_back(test::halfspace_anchor("bottom", Vec3(0, 0, kH), Vec3(0, 0, -1)));
  s.anchors.push_back(test::halfspace_anchor("left", Vec3(kH, 0, 0), Vec3(-1, 0, 0)));
  s.anchors.push_back(test::halfspace_anchor("right", Vec3(6 * kH, 0, 0), Vec3(1, 0, 0)));
  s.anchors.push_back(test::halfspace_anchor("front", Vec3(0, kH, 0), Vec3(0, -1, 0)));
  s.anchors.push_back(test::halfspace_anchor("back", Vec3(0, 6 * kH, 0), Vec3(0, 1, 0)));
  IndenterSpec probe;
  probe.kind = IndenterSpec::Kind::Sphere;
  probe.radius_m = 0.004;
  probe.start_m = Vec3(3.5 * kH, 3.5 * kH, 6.5 * kH + probe.radius_m);
  probe.velocity_m_s = Vec3(0, 0, -0.005);  // the direction of the press
  s.indenters.push_back(probe);
  s.solver.precision = Precision::Double;
  s.solver.check_every = 20;
  s.stop.equilibrium = 1e-9;
  return s;
}

TEST(CurveFit, RecoversBiphasicSpringParametersOfThePapersCube) {
  const double E = 4000, c3 = 8, ec = 0.2;
  const Scene truth = paper_cube(E, c3, ec);
  const test::Model m = test::make_model(truth);
  ASSERT_EQ(m.lattice.element_count(), 343u);
  // The "measured" curve: 8 mm of travel in 0.5 mm steps.
  ForceCurve measured;
  for (int k = 0; k <= 16; ++k) measured.travel_m.push_back(0.5e-3 * k);
  measured.force_n = press_curve_forces(truth, m.lattice, m.elements, test::cl_context(), measured.travel_m);
  std::cout << "measured: ";
  for (double f : measured.force_n) std::cout << f << " ";
  std::cout << "N\n";
  for (int k = 1; k <= 16; ++k) ASSERT_GT(measured.force_n[k], measured.force_n[k - 1]) << "level " << k;
  // Nonlinear: the second 4 mm take 18% more force than the first (a linear press: ~0%).
  EXPECT_GT(measured.force_n[16] - measured.force_n[8], 1.1 * measured.force_n[8]);

  const Scene start = paper_cube(1.5 * E, 0.5 * c3, 1.4 * ec);
  CurveFitOptions options;
  options.points = 8;  // every 1 mm
  const CurveFitResult r = fit_force_curve(start, m.lattice, test::cl_context(), measured, options,
                                           [](int n, double rel) { std::cout << "  evaluation " << n << ": relative RMS " << rel << "\n"; });
  std::cout << r.status << " after " << r.evaluations << " evaluations, " << r.iterations << " iterations; RMS "
            << r.start_rms_n << " N → " << r.rms_n << " N (" << 100 * r.relative_rms << "%)\n";
  for (const FitValue& p : r.parameters) std::cout << "  " << p.name << " " << p.start << " → " << p.fitted << "\n";
  ASSERT_EQ(r.parameters.size(), 3u);
  // The curve comes from the same model, so the fit should land on the truth: within 1% (it
  // lands within 1e-5 on PoCL) and an RMS error under 1e-4 of the largest force.
  EXPECT_NEAR(r.parameters[0].fitted / E, 1, 0.01);
  EXPECT_NEAR(r.parameters[1].fitted / c3, 1, 0.01);
  EXPECT_NEAR(r.parameters[2].fitted / ec, 1, 0.01);
  EXPECT_LT(r.relative_rms, 1e-4);
  EXPECT_LT(r.rms_n, 1e-3 * r.start_rms_n);
  EXPECT_NE(r.status.find("converged"), std::string::npos) << r.status;
}

// The same cube as a one-term Ogden solid (μ = 1000 Pa, α = 4; μ0 = μα/2 = 2 kPa) pressed 4 mm:
// μ and α come back from a start 50% and 35% off.
TEST(CurveFit, RecoversOgdenParameters) {
  auto ogden_cube = [](double mu, double alpha) {
    Scene s = paper_cube(3000, 1, 0.1);
    MaterialSpec& m = s.materials["soft"];
    m.law = "ogden";
    m.ogden_mu_pa = {mu};
    m.ogden_alpha = {alpha};
    m.poisson_ratio = 0.45;
    s.stop.equilibrium = 1e-8;
    return s;
  };
  const Scene truth = ogden_cube(1000, 4);
  const test::Model m = test::make_model(truth);
  ForceCurve measured;
  for (int k = 0; k <= 4; ++k) measured.travel_m.push_back(1e-3 * k);
  measured.force_n = press_curve_forces(truth, m.lattice, m.elements, test::cl_context(), measured.travel_m);
  for (int k = 1; k <= 4; ++k) ASSERT_GT(measured.force_n[k], measured.force_n[k - 1]) << "level " << k;
  const Scene start = ogden_cube(1500, 2.6);
  CurveFitOptions options;
  options.points = 4;  // every 1 mm: hyperelastic presses cost more, so fewer levels
  const CurveFitResult r = fit_force_curve(start, m.lattice, test::cl_context(), measured, options);
  std::cout << r.status << " after " << r.evaluations << " evaluations; RMS " << r.start_rms_n << " N → " << r.rms_n
            << " N (" << 100 * r.relative_rms << "%)\n";
  for (const FitValue& p : r.parameters) std::cout << "  " << p.name << " " << p.start << " → " << p.fitted << "\n";
  ASSERT_EQ(r.parameters.size(), 2u);
  EXPECT_NEAR(r.parameters[0].fitted / 1000, 1, 0.01);
  EXPECT_NEAR(r.parameters[1].fitted / 4, 1, 0.01);
  EXPECT_LT(r.relative_rms, 1e-4);
}

TEST(CurveFit, ParametersMustSuitTheLaw) {
  MaterialSpec linear = test::material("soft", 3000);
  EXPECT_NO_THROW(check_fit_parameter(linear, "E"));
  EXPECT_THROW(check_fit_parameter(linear, "cubic"), Error);
  EXPECT_THROW(check_fit_parameter(linear, "mu"), Error);
  EXPECT_THROW(check_fit_parameter(linear, "stiffness"), Error);
  MaterialSpec ogden = test::validation_material("ogden", 0.45);  // two terms
  EXPECT_THROW(check_fit_parameter(ogden, "mu"), Error);
  for (const char* name : {"E", "cubic", "critical_strain", "mu", "alpha"}) {
    const double like = std::string(name) == "alpha" ? -2.0 : 0.3;
    EXPECT_NEAR(from_coordinate(name, to_coordinate(name, like), like), like, 1e-12) << name;
  }
}

}  // namespace
}  // namespace vb
