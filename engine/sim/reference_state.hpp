#pragma once
/// The unloaded reference state (docs/PHYSICS.md §13). A CT is taken under gravity, so its shape
/// is a loaded one. The estimate finds rest offsets u0 (each element rests at its voxel centre
/// plus u0) such that the model, loaded by the CT posture's gravity, lands on the CT: the fixed
/// point of Sellier's iteration u0 ← u0 − u*(u0), where u*(u0) is the equilibrium displacement
/// from the CT under the CT's gravity with rest offsets u0. Each u* is a dynamic-relaxation solve.
#include <cstdint>
#include <functional>
#include <vector>

#include "engine/sim/run.hpp"
#include "engine/sim/simulator.hpp"

namespace vb {

struct ReferenceIteration {
  int iteration = 0;          ///< 1-based
  double residual_max_m = 0;  ///< largest |u*| over free elements (but unsupported ones, below):
                              ///< how far the model lands from the CT
  double residual_rms_m = 0;  ///< RMS |u*| over them (both +inf for an unstable solve)
  std::int64_t steps = 0;     ///< relaxation steps of this forward solve
  double step = 1;            ///< β of the update u0 − β·u* tried (1 for the first solve)
};

struct ReferenceState {
  std::vector<double> rest_offset_m;  ///< n×3, world frame (m); zero for held elements
  std::vector<ReferenceIteration> history;  ///< every forward solve, rejected steps included
  bool converged = false;      ///< the last residual is within [reference_state] tolerance
  double residual_max_m = 0;   ///< of the returned rest offsets (the last iteration's)
  double residual_rms_m = 0;
  double max_rest_offset_m = 0;  ///< largest |u0|: how far the unloaded shape is from the CT
  /// free elements left out of the residual: their neighbours lie in a plane or a line (one-voxel
  /// sheets and strands), so nothing holds them at their CT position against gravity across it
  std::size_t unsupported_elements = 0;
  std::int64_t steps = 0;        ///< all forward solves together
  double wall_time_s = 0;
};

/// The scene the forward solves run: the CT's gravity, anchors at their CT pose (no roll, pitch
/// or yaw), no indenters, device or volume constraint, dynamic relaxation to a residual of at
/// most 10⁻⁶.
Scene reference_state_scene(const Scene& scene);

/// Runs the iteration on `cl` (its own simulator) until the residual is within tolerance or
/// [reference_state] max_iterations forward solves are done (then `converged` is false). A step
/// that lands farther from the CT (or goes unstable) is retried shorter: history lists every
/// solve, and the result keeps the best rest offsets. `on_iteration` is
/// called after each forward solve, `on_step` at each equilibrium check of a solve. Throws vb::Error when a forward solve does not reach
/// equilibrium or goes unstable.
ReferenceState estimate_reference_state(const Scene& scene, const Lattice& lattice, const ClContext& cl,
                                        const std::function<void(const ReferenceIteration&)>& on_iteration = {},
                                        const std::function<void(const RunProgress&)>& on_step = {});

/// The same with the caller's element arrays (e.g. a fit's trial moduli; built for this scene and
/// lattice) and a first estimate of the rest offsets (n×3; empty: zero, the CT as rest shape). A
/// first estimate close to the answer (the previous moduli's) lands within tolerance in fewer
/// forward solves.
ReferenceState estimate_reference_state(const Scene& scene, const Lattice& lattice, const ElementArrays& elements,
                                        const ClContext& cl, const std::vector<double>& first_offset_m,
                                        const std::function<void(const ReferenceIteration&)>& on_iteration = {},
                                        const std::function<void(const RunProgress&)>& on_step = {});

/// The same on the caller's simulator of reference_state_scene(scene) with these element arrays
/// (built with them, or given them by Simulator::set_materials): a fit keeps one across its
/// solves (engine/fit/reference_forward.hpp). Its rest offsets and state are the iteration's.
ReferenceState estimate_reference_state(Simulator& sim, const Scene& scene, const Lattice& lattice,
                                        const ElementArrays& elements, const std::vector<double>& first_offset_m,
                                        const std::function<void(const ReferenceIteration&)>& on_iteration = {},
                                        const std::function<void(const RunProgress&)>& on_step = {});

}  // namespace vb
