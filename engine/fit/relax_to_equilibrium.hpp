#pragma once
/// Relaxing a forward solve's simulator to static equilibrium under one gravity (docs/FIT.md,
/// "Forward model").
#include <cstdint>

#include "engine/sim/run.hpp"
#include "engine/sim/simulator.hpp"

namespace vb {

/// Sets gravity g, restarts the clock and steps until at_equilibrium (engine/sim/run.hpp) holds at
/// tolerance scene.stop.equilibrium on `scales` (checked every solver.check_every steps): the
/// residual and, for relaxation, the distance still to go; returns the steps. Throws vb::Error
/// (naming the posture) for a non-finite state or when scene.stop.max_steps pass first.
std::int64_t relax_to_equilibrium(Simulator& sim, const Scene& scene, const EquilibriumScales& scales, const Vec3& g,
                                  const char* posture);

}  // namespace vb
