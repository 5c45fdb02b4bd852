#include "engine/curve_fit/press_curve.hpp"

#include <cmath>

#include "engine/error.hpp"
#include "engine/sim/run.hpp"

namespace vb {

std::vector<double> press_curve_forces(const Scene& scene_in, const Lattice& lattice, const ElementArrays& elements,
                                       const ClContext& cl, const std::vector<double>& travel_m,
                                       const PressCurveOptions& o) {
  require(o.probe < scene_in.indenters.size(), "the scene has no [[indenter]] to press with", "indenter");
  const IndenterSpec& ind = scene_in.indenters[o.probe];
  require(ind.velocity_m_s.norm() > 0, "the pressing indenter has no velocity, so no press direction",
          "indenter " + std::to_string(o.probe + 1), "give it a velocity along the press (its speed does not matter)");
  Scene scene = scene_in;  // the simulator keeps a reference: it lives as long as sim
  scene.solver.integrator = Integrator::Relaxation;
  const Vec3 direction = ind.velocity_m_s.normalized();
  const double h = lattice.spacing_m, tol = scene.stop.equilibrium;
  require(tol > 0, "a force curve needs an equilibrium tolerance", "stop.equilibrium", "set it, e.g. 1e-7");
  const EquilibriumScales scales = equilibrium_scales(lattice, elements);
  const std::int64_t check_every = std::max(1, scene.solver.check_every);
  const std::int64_t max_steps = o.max_steps_per_level > 0 ? o.max_steps_per_level : scene.stop.max_steps;

  Simulator sim(scene, lattice, elements, cl);
  std::vector<double> forces;
  double previous = 0;
  for (const double d : travel_m) {
    require(d >= previous, "press travels must be ascending and non-negative", "curve");
    // At most a hundredth of a spacing per step: contact stays a gentle push.
    const std::int64_t ramp = std::max<std::int64_t>(1, std::int64_t(std::ceil((d - previous) / (0.01 * h))));
    const double t0 = sim.time_s();
    sim.set_indenter_motion(o.probe, IndenterMotion::straight(ind.start_m + previous * direction,
                                                              ind.start_m + d * direction, t0,
                                                              t0 + double(ramp) * sim.dt_s()));
    const std::int64_t level_start = sim.steps();
    for (;;) {
      sim.advance(check_every);
      const StateCheck c = sim.check();
      require(c.nonfinite_elements == 0 && c.max_speed_m_s * sim.dt_s() <= 0.5 * h,
              "the press blew up at a travel of " + std::to_string(1e3 * d) + " mm", "solver",
              "use a smaller solver.dt, or check the material parameters");
      if (sim.steps() - level_start >= ramp && at_equilibrium(sim, c, scales, tol)) {
        forces.push_back(-c.indenter_force_n[o.probe].dot(direction));
        break;
      }
      require(sim.steps() - level_start < max_steps,
              "no equilibrium at a travel of " + std::to_string(1e3 * d) + " mm after " + std::to_string(max_steps) +
                  " steps (residual " + std::to_string(c.residual_ratio) + ")",
              "stop.equilibrium", "loosen the tolerance, raise stop.max_steps, or check the anchors hold the model");
    }
    previous = d;
  }
  return forces;
}

}  // namespace vb
