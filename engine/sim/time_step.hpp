#pragma once
/// Stable explicit time step: bounds on the stiffest mode and damping, and the largest step
/// for which the integrator's amplification stays ≤ 1 on every mode up to that bound.
#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/element_setup.hpp"

namespace vb {

struct StabilityBounds {
  double omega_max = 0;    ///< upper bound on the highest angular frequency (rad/s), Gershgorin
  double damping_max = 0;  ///< upper bound on the highest modal damping rate c (1/s), incl. global
};

/// Gershgorin bounds of M⁻¹K and M⁻¹C (+ global damping) over the free elements; `extra_row_n_m`
/// (per element, N/m, or empty) is stiffness added to each of its rows (triangle contact's penalty).
StabilityBounds stability_bounds(const Lattice& lattice, const ElementArrays& elements,
                                 double dashpot_ratio, double global_damping_per_s,
                                 const std::vector<double>& extra_row_n_m = {});

/// Per free element the largest Gershgorin row of its elastic stiffness (N/m; 0 for held ones).
std::vector<double> element_row_stiffness_n_m(const Lattice& lattice, const ElementArrays& elements);

/// Dynamic relaxation's mass scaling (kernels/relax.cl): per element m/m̃ ≥ 1, chosen so that
/// every free element's Gershgorin bound with its scaled mass m̃ equals the model's ω_max;
/// 1 for held elements. With `extra_row_n_m` (triangle contact's penalty, per element) the bound
/// includes it while ω_max stays the elastic one: those elements get heavier (m/m̃ < 1) and the
/// step stays.
std::vector<double> relaxation_mass_scale(const Lattice& lattice, const ElementArrays& elements,
                                          const std::vector<double>& extra_row_n_m = {});
/// The same from each element's largest stiffness row (element_row_stiffness_n_m, which a
/// relaxation scene's TimeStepChoice holds), so a simulator walks the lattice once for both.
std::vector<double> relaxation_mass_scale(const ElementArrays& elements, const std::vector<double>& row_stiffness_n_m,
                                          const std::vector<double>& extra_row_n_m = {});

/// Largest dt for which the integrator is stable on ẍ = −ω²x − c(ω)ẋ for all ω ≤ ω_max, with
/// c(ω) = γ + (c_max − γ)(ω/ω_max)² (dashpots are stiffness-proportional, global damping not).
/// Returns 0 when no positive step is stable (Heun without any damping).
double stable_time_step(Integrator integrator, const StabilityBounds& bounds, double global_damping_per_s);

/// Spectral radius of one step of the integrator on the scalar mode (ω, c) with step dt.
double amplification(Integrator integrator, double omega, double c, double dt);

struct TimeStepChoice {
  double dt_s = 0;
  bool automatic = true;
  double stable_limit_s = 0;  ///< the bound's stable step (s)
  StabilityBounds bounds;
  /// relaxation scenes only: element_row_stiffness_n_m, the rows the bounds came from (the
  /// mass scale is made from them too); empty otherwise
  std::vector<double> row_stiffness_n_m;
};

/// dt from the scene: "auto" → dt_safety × stable limit; an explicit dt is used as given.
/// Throws vb::Error when "auto" finds no stable step.
TimeStepChoice choose_time_step(const Scene& scene, const Lattice& lattice, const ElementArrays& elements);

}  // namespace vb
