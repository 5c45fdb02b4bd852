// Undamped single-mode oscillation: the centre element of a 3×3×3 block whose 26 neighbours are
// held moves along z only (the mirror symmetries cancel x and y forces): a 1-DOF oscillator.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/material/linear_spring.hpp"
#include "engine/sim/host_reference.hpp"
#include "engine/sim/simulator.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

/// Largest relative energy error over `periods` periods, for one integrator at ω·dt.
double max_energy_error(Integrator integrator, double omega_dt, int periods) {
  const double h = 0.002;
  Scene s = test::box_scene(3, 3, 3, h);
  s.solver.integrator = integrator;
  s.solver.precision = Precision::Double;
  s.solver.dashpot_ratio = 0;
  auto m = test::make_model(s);
  const std::size_t centre = std::size_t(m.lattice.element_of_voxel[1 + 3 * (1 + 3 * 1)]);
  for (std::size_t e = 0; e < m.lattice.element_count(); ++e)  // hold all but the centre
    if (e != centre) m.elements.inverse_mass[e] = 0;
  m.elements.held_count = m.lattice.element_count() - 1;

  const auto k = connection_stiffness(m.lattice, m.elements.youngs_modulus_pa, centre);
  double k_z = 0;  // small-amplitude stiffness along z
  for (int d = 0; d < 26; ++d) {
    const auto& o = neighbour_offsets()[d];
    k_z += k[d] * o[2] * o[2] / (o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
  }
  const double mass = m.elements.mass_kg[centre];
  const double omega = std::sqrt(k_z / mass);
  s.solver.dt_s = omega_dt / omega;

  Simulator sim(s, m.lattice, m.elements, test::cl_context());
  std::vector<double> u(3 * m.lattice.element_count(), 0.0), v(u.size(), 0.0);
  const double amplitude = 1e-4 * h;  // small: the spring nonlinearity is negligible
  u[3 * centre + 2] = amplitude;
  sim.upload(u, v);
  auto energy = [&](const std::vector<double>& uu, const std::vector<double>& vv) {
    double pe = 0;
    for (int d = 0; d < 26; ++d) {
      const auto& o = neighbour_offsets()[d];
      const Vec3 r = h * Vec3(o[0], o[1], o[2]) - Vec3(uu[3 * centre], uu[3 * centre + 1], uu[3 * centre + 2]);
      const double stretch = r.norm() - h * linear_spring::rest_length_factor(d);
      pe += 0.5 * k[d] * stretch * stretch;
    }
    const Vec3 vc(vv[3 * centre], vv[3 * centre + 1], vv[3 * centre + 2]);
    return pe + 0.5 * mass * vc.squaredNorm();
  };
  const double e0 = energy(u, v);
  const int steps = int(std::ceil(periods * 2 * M_PI / omega_dt));
  double worst = 0;
  for (int i = 0; i < steps; ++i) {
    sim.advance(1);
    sim.download(u, v);
    worst = std::max(worst, std::abs(energy(u, v) - e0) / e0);
  }
  return worst;
}

TEST(Integrators, HeunEnergyErrorIsSmallerThanSymplecticEuler) {
  const double omega_dt = 0.1;
  const double euler = max_energy_error(Integrator::SymplecticEuler, omega_dt, 5);
  const double heun = max_energy_error(Integrator::Heun, omega_dt, 5);
  RecordProperty("euler_max_energy_error", std::to_string(euler));
  RecordProperty("heun_max_energy_error", std::to_string(heun));
  // Symplectic Euler's energy oscillates by about ω·dt/2; Heun's grows by (ω·dt)⁴/8 per step.
  EXPECT_NEAR(euler, omega_dt / 2, 0.3 * omega_dt / 2);
  EXPECT_LT(heun, 0.5 * euler) << "heun " << heun << " euler " << euler;
  EXPECT_GT(heun, 0.0);
}

TEST(Integrators, HeunIsSecondOrderAccurate) {
  // Halving dt cuts Heun's energy error over a fixed time about 8× for a linear oscillator
  // ((ω dt)⁴ per step × 1/dt steps → dt³), Euler's only about 2×.
  const double heun_coarse = max_energy_error(Integrator::Heun, 0.2, 3);
  const double heun_fine = max_energy_error(Integrator::Heun, 0.1, 3);
  const double euler_coarse = max_energy_error(Integrator::SymplecticEuler, 0.2, 3);
  const double euler_fine = max_energy_error(Integrator::SymplecticEuler, 0.1, 3);
  RecordProperty("heun_ratio_dt_halved", std::to_string(heun_coarse / heun_fine));
  RecordProperty("euler_ratio_dt_halved", std::to_string(euler_coarse / euler_fine));
  EXPECT_GT(heun_coarse / heun_fine, 6.0);
  EXPECT_LT(euler_coarse / euler_fine, 2.5);
}

}  // namespace
}  // namespace vb
