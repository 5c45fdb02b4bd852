#pragma once
/// Quasi-static probing ([probe], docs/PROBING.md): gravity settling, then a line of presses, each
/// from the settled state, in depth increments brought to equilibrium one by one.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "engine/sim/element_setup.hpp"
#include "engine/sim/simulator.hpp"

namespace vb {

/// One equilibrium of a press.
struct PressSample {
  double depth_m = 0;                 ///< indenter travel from the press's zero point (m)
  Vec3 force_n = Vec3::Zero();        ///< force the tissue exerts on the indenter (N, world)
  double press_force_n = 0;           ///< its component against the press direction (N, > 0 pushing back)
  std::int64_t contact_elements = 0;  ///< elements the indenter carries force from
  double contact_area_m2 = 0;         ///< their surface-area shares (engine/surface/surface_area.hpp)
  std::int64_t steps = 0;             ///< solver steps this increment took
  double residual = 0;                ///< max residual / F_ref at the end of the increment
  bool converged = false;
  double min_det_f = 1;               ///< smallest det F over the free elements (host fit, element_measures)
  std::int64_t inverted_elements = 0; ///< free elements with det F ≤ 0: the lattice folded, the force is void
};

struct PressResult {
  Vec3 start_m = Vec3::Zero();        ///< the indenter's reference point at zero depth (m)
  double position_m = 0;              ///< distance of the press's start along the line from `from` (m)
  std::vector<PressSample> samples;   ///< depth 0 (the settled state) and each increment
  double peak_force_n = 0;            ///< press force at the full depth (N)
  double stiffness_n_m = 0;           ///< slope of the last increment (N/m)
  std::vector<double> depth_at_force_m;  ///< per [probe] at_force: depth (m), NaN when not reached
  double min_det_f = 1;               ///< smallest det F over the press's increments
  bool inverted = false;              ///< some increment folded an element (det F ≤ 0): not a valid press
};

struct ProbeResult {
  std::int64_t settle_steps = 0;
  double settle_residual = 0;
  bool settled = false;               ///< settling reached the equilibrium tolerance
  double settle_max_displacement_m = 0;
  std::vector<PressResult> presses;
  std::int64_t unconverged_increments = 0;
  std::int64_t inverted_increments = 0;  ///< increments that ended with an element folded (det F ≤ 0)
  std::int64_t total_steps = 0;
  double wall_time_s = 0;
};

/// Progress callback: press index (−1 while settling), increment, residual.
using ProbeProgress = std::function<void(int press, int increment, double residual)>;

/// Runs the [probe] protocol of `scene` on `sim` (a fresh simulator of that scene). Throws vb::Error
/// when the scene has no [probe], when the state stops being finite, or when a press never touches.
ProbeResult run_press_line(const Scene& scene, const Lattice& lattice, const ElementArrays& elements, Simulator& sim,
                           const ProbeProgress& progress = {});

}  // namespace vb
