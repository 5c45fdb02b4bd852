#include "engine/fit/relax_to_equilibrium.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "engine/error.hpp"

namespace vb {

std::int64_t relax_to_equilibrium(Simulator& sim, const Scene& scene, const EquilibriumScales& scales, const Vec3& g,
                                  const char* posture) {
  sim.set_gravity(g);
  sim.restart_clock();
  const std::int64_t every = std::max(1, scene.solver.check_every);
  for (;;) {
    sim.advance(every);
    const StateCheck c = sim.check();
    require(c.nonfinite_elements == 0 && std::isfinite(c.residual_ratio),
            "the forward solve went unstable (non-finite state)", std::string("fit, posture ") + posture,
            "a modulus bound may be too wide: set fit.min_E / fit.max_E");
    if (at_equilibrium(sim, c, scales, scene.stop.equilibrium)) return sim.steps();
    require(sim.steps() < scene.stop.max_steps,
            "the forward solve did not reach equilibrium in " + std::to_string(scene.stop.max_steps) +
                " steps (residual " + std::to_string(c.residual_ratio) + ")",
            std::string("fit, posture ") + posture, "raise fit.max_steps or fit.equilibrium");
  }
}

}  // namespace vb
