#pragma once
/// Relaxing a forward solve's simulator to static equilibrium under one gravity (docs/FIT.md,
/// "Forward model").
#include <cstdint>

#include "engine/sim/simulator.hpp"

namespace vb {

/// Sets gravity g, restarts the clock and steps until the largest residual force on a free
/// element is ≤ scene.stop.equilibrium · force_scale_n (checked every solver.check_every steps);
/// returns the steps. Throws vb::Error (naming the posture) for a non-finite state or when
/// scene.stop.max_steps pass first.
std::int64_t relax_to_equilibrium(Simulator& sim, const Scene& scene, double force_scale_n, const Vec3& g,
                                  const char* posture);

}  // namespace vb
