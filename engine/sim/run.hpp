#pragma once
/// The run loop around the simulator: stepping in chunks between device checks, stopping rules
/// (equilibrium, max steps, simulated time), blow-up detection, frames, and the final results.
#include <functional>
#include <optional>
#include <string>

#include "engine/sim/run_result.hpp"
#include "engine/sim/simulator.hpp"

namespace vb {

struct RunProgress {
  std::int64_t step = 0, max_steps = 0;
  double time_s = 0;
  double residual = 0;     ///< max residual force / F_ref
  double speed_ratio = 0;  ///< max speed / elastic wave speed
};

struct RunOutput {
  RunSummary summary;
  FinalState state;
  Frames frames;
};

/// Runs to a stopping rule. Throws vb::Error (with step, element and a smaller-dt hint) when the
/// state stops being finite or an element moves more than half a spacing in one step.
RunOutput run_simulation(const Scene& scene, const Lattice& lattice, const ElementArrays& elements,
                         Simulator& sim, const std::function<void(const RunProgress&)>& progress = {},
                         bool refuse_penetrating_start = true);

/// Model-wide scales (docs/SCENE.md, "Equilibrium criterion"). The residual and speed tests scale
/// each element by its own tissue on the device (StateCheck's ratios); these are the stiffest free
/// tissue's, for bounds such as the haptic probe's stiffness, and the size relaxation's test uses.
struct EquilibriumScales {
  double force_n = 0;         ///< E_max·h²
  double wave_speed_m_s = 0;  ///< √(E_max/ρ_min)
  double size_m = 0;          ///< L, the lattice's diagonal
};
EquilibriumScales equilibrium_scales(const Lattice& lattice, const ElementArrays& elements);

/// Whether check c meets the equilibrium criterion at tolerance tol: every free element's residual
/// force ≤ tol·E·h² and, for the dynamic integrators, its speed ≤ tol·√(E/ρ), E the largest
/// modulus of the element and its free hyperelastic neighbours (StateCheck's ratios); for relaxation, whose
/// speeds are fictitious, the distance still to go, max speed / ω_min ≤ tol·L instead (its slowest
/// mode decays as e^(−ω_min·t); docs/PHYSICS.md, "Fast equilibrium"). Runs, probe presses, force
/// curves and fit solves stop on it.
bool at_equilibrium(const Simulator& sim, const StateCheck& c, const EquilibriumScales& scales, double tol);

/// Why a dynamic float run may have stopped short of the criterion, or nothing: its residual met
/// the tolerance and its speed did not, at a tolerance near float's round-off (the residual's floor
/// is ~4·10⁻⁷), where round-off rather than dynamics can keep a speed up. Contact did, until push
/// contact took distances within float's resolution as zero (docs/VALIDATION.md, "Contact inside
/// the band": the phantom's tightest ring at 10⁻⁶ ran float to max_steps 60,000; it now settles
/// in 2,700 steps, as double does).
std::optional<std::string> float_floor_hint(const Scene& scene, const RunSummary& summary);

/// Element nearest to a world point (m).
std::size_t nearest_element(const Lattice& lattice, const Vec3& point_m);

}  // namespace vb
