#pragma once
/// The unloaded reference state (docs/PHYSICS.md §13). A CT is taken under gravity, so its shape
/// is a loaded one. The estimate finds rest offsets u0 (each element rests at its voxel centre
/// plus u0) such that the model, loaded by the CT posture's gravity, lands on the CT: the fixed
/// point of Sellier's iteration u0 ← u0 − u*(u0), where u*(u0) is the equilibrium displacement
/// from the CT under the CT's gravity with rest offsets u0. Each u* is a dynamic-relaxation solve.
#include <cstdint>
#include <functional>
#include <vector>

#include "engine/sim/simulator.hpp"

namespace vb {

struct ReferenceIteration {
  int iteration = 0;          ///< 1-based
  double residual_max_m = 0;  ///< largest |u*| over free elements: how far the model lands from the CT
  double residual_rms_m = 0;  ///< RMS |u*| over free elements
  std::int64_t steps = 0;     ///< relaxation steps of this forward solve
};

struct ReferenceState {
  std::vector<double> rest_offset_m;  ///< n×3, world frame (m); zero for held elements
  std::vector<ReferenceIteration> history;
  bool converged = false;      ///< the last residual is within [reference_state] tolerance
  double residual_max_m = 0;   ///< of the returned rest offsets (the last iteration's)
  double residual_rms_m = 0;
  double max_rest_offset_m = 0;  ///< largest |u0|: how far the unloaded shape is from the CT
  std::int64_t steps = 0;        ///< all forward solves together
  double wall_time_s = 0;
};

/// The scene the forward solves run: the CT's gravity, anchors at their CT pose (no roll, pitch
/// or yaw), no indenters, device or volume constraint, dynamic relaxation to a residual of at
/// most 10⁻⁶.
Scene reference_state_scene(const Scene& scene);

/// Runs the iteration on `cl` (its own simulator) until the residual is within tolerance or
/// [reference_state] max_iterations is reached (then `converged` is false). `on_iteration` is
/// called after each forward solve. Throws vb::Error when a forward solve does not reach
/// equilibrium or goes unstable.
ReferenceState estimate_reference_state(const Scene& scene, const Lattice& lattice, const ClContext& cl,
                                        const std::function<void(const ReferenceIteration&)>& on_iteration = {});

}  // namespace vb
