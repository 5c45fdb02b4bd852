// Batched forward solves (docs/FIT.md, "Batched solves"): the Jacobian's perturbed solves differ
// only in their moduli, so K copies of the model lie side by side on one grid (tile_lattice) and
// one simulator relaxes them together: one kernel launch per step and one check per
// check_every steps for all K, and K times the work per launch, which a GPU needs to fill
// itself on a small model.
//
// What the copies share: the time step and the relaxation mass scaling (set by the stiffest
// element of all copies) and the adaptive damping c = 2·√(smallest Rayleigh quotient seen),
// whose sums run over all copies. Neither moves an equilibrium, only the path to it. The
// pooled quotient is a weighted mean of the copies' own quotients, each ≥ that copy's ω_min², so
// c tends to 2·min_k ω_min,k: a copy whose slowest mode is faster is then damped a little under
// critically, and its slowest mode still decays at rate min_k ω_min,k. Perturbed copies differ
// by one step_log (5%) in one region's E, i.e. ≤ 2.5% in ω, so a batch needs about the steps of
// its slowest copy alone (measured: docs/FIT.md). Convergence is the strictest copy's tolerance
// over every element of every copy, so each copy is at least as converged as when solved alone.
#include <algorithm>
#include <chrono>
#include <memory>

#include "engine/error.hpp"
#include "engine/fit/forward_model.hpp"
#include "engine/fit/relax_to_equilibrium.hpp"
#include "engine/lattice/tiled_lattice.hpp"
#include "engine/sim/run.hpp"
#include "engine/sim/simulator.hpp"

namespace vb {
namespace {

/// The copies' element arrays one after another; with `own_rows` each copy's material table too
/// (its tissue ids are then offset by the table's size, tile_lattice's tissue_stride).
ElementArrays concatenate(const std::vector<ElementArrays>& parts, bool own_rows) {
  ElementArrays out;
  out.hyperelastic = parts.front().hyperelastic;
  out.biphasic = parts.front().biphasic;
  out.material_table = parts.front().material_table;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const ElementArrays& p = parts[k];
    for (auto [to, from] : {std::pair{&out.youngs_modulus_pa, &p.youngs_modulus_pa},
                            std::pair{&out.stability_modulus_pa, &p.stability_modulus_pa},
                            std::pair{&out.mass_kg, &p.mass_kg}, std::pair{&out.inverse_mass, &p.inverse_mass},
                            std::pair{&out.displacement_m, &p.displacement_m}})
      to->insert(to->end(), from->begin(), from->end());
    out.held_count += p.held_count;
    if (own_rows && k > 0) out.material_table.insert(out.material_table.end(), p.material_table.begin(), p.material_table.end());
  }
  return out;
}

std::vector<double> repeated(const std::vector<double>& state, std::size_t copies) {
  std::vector<double> out;
  out.reserve(state.size() * copies);
  for (std::size_t k = 0; k < copies; ++k) out.insert(out.end(), state.begin(), state.end());
  return out;
}

/// copy k's n×3 block of a batch state
std::vector<double> block(const std::vector<double>& state, std::size_t k, std::size_t n) {
  return {state.begin() + std::ptrdiff_t(3 * n * k), state.begin() + std::ptrdiff_t(3 * n * (k + 1))};
}

}  // namespace

std::size_t ForwardModel::batch_size() const {
  if (fit_.batch == 1 || unloaded_ || scene_.volume.preserve || scene_.reference_state.active) return 1;
  const Lattice& lat = lattice();
  const bool hyper = has_hyperelastic_tissue(scene_, lat);  // a tissue table row per copy
  std::size_t most = hyper ? 256 / std::max<std::size_t>(1, lat.tissue_names.size()) : 256;
  if (fit_.batch > 1) {
    require(std::size_t(fit_.batch) <= most,
            "fit.batch = " + std::to_string(fit_.batch) + " copies of " + std::to_string(lat.tissue_names.size()) +
                " hyperelastic (tissue, region) pairs need more than 256 tissue ids",
            "fit.batch", "use batch = " + std::to_string(most) + " or \"auto\"");
    return std::size_t(fit_.batch);
  }
  // auto: one at a time on every device. Measured (docs/FIT.md, "Batched solves"): a batch runs
  // every copy for as many steps as its slowest (K·max instead of Σ steps: 23% more element-steps
  // on the 38.7k-element phantom); it was slower per Jacobian on PoCL (+12%) and on an H200 (0.17–
  // 0.21 against 0.150–0.156 s one at a time, 2026-12-03: the GPU relaxes the batch 2.6× faster, but the nine
  // copies' new moduli cost as much host time as nine solves' and the batch's relaxation saves less;
  // docs/FIT.md). Batches stay available as fit.batch = N.
  return 1;
}

std::vector<ForwardSolution> ForwardModel::solve_batch(const std::vector<std::vector<double>>& moduli,
                                                       const ForwardSolution* warm) const {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  PhaseLaps lap(&timing_);
  ++timing_.jacobians;
  timing_.columns += moduli.size();
  std::vector<ForwardSolution> out;
  out.reserve(moduli.size());
  const std::size_t most = batch_size();
  const Lattice& lat = lattice();
  const std::size_t n = lat.element_count();
  for (std::size_t first = 0; first < moduli.size(); first += most) {
    const std::size_t K = std::min(most, moduli.size() - first);
    if (K == 1) {
      out.push_back(solve_timed(moduli[first], warm, &timing_));  // it laps its own phases
      lap.restart();
      continue;
    }
    std::vector<ElementArrays> parts;
    EquilibriumScales scales{INFINITY, INFINITY, INFINITY};  // the strictest copy's, one copy's size
    for (std::size_t k = 0; k < K; ++k) {
      parts.push_back(arrays(moduli[first + k]));
      const EquilibriumScales s = equilibrium_scales(lat, parts.back());
      scales = {std::min(scales.force_n, s.force_n), std::min(scales.wave_speed_m_s, s.wave_speed_m_s),
                std::min(scales.size_m, s.size_m)};
    }
    const bool own_rows = parts.front().hyperelastic;  // per-copy μ, κ rows; springs read E per element
    const ElementArrays el = concatenate(parts, own_rows);
    parts.clear();
    BatchSimulator& kept = batch_sims_[K];
    if (!kept.sim) {
      kept.lattice = std::make_unique<Lattice>(tile_lattice(lat, int(K), own_rows ? int(lat.tissue_names.size()) : 0));
      kept.sim = std::make_unique<Simulator>(scene_, *kept.lattice, el, cl_);
      ++timing_.simulators;
    } else {
      kept.sim->set_materials(el);  // as a simulator built with el starts
    }
    Simulator& sim = *kept.sim;
    solves_ += K;
    const std::vector<double> zeros(3 * n * K, 0.0);
    lap(&JacobianTiming::setup_s);
    std::vector<double> from(3 * n * K, 0.0), to, v;
    std::int64_t steps = 0;
    if (fit_.from_gravity_m_s2) {
      if (warm) sim.upload(repeated(warm->from_m, K), zeros);
      lap(&JacobianTiming::upload_s);
      steps += relax_to_equilibrium(sim, scene_, scales, *fit_.from_gravity_m_s2, "from");
      lap(&JacobianTiming::relax_s);
      sim.download(from, v);
      lap(&JacobianTiming::readback_s);
    }
    if (warm) sim.upload(repeated(warm->to_m, K), zeros);
    else if (fit_.from_gravity_m_s2) sim.upload(from, zeros);
    lap(&JacobianTiming::upload_s);
    steps += relax_to_equilibrium(sim, scene_, scales, scene_.gravity.acceleration_m_s2, "to");
    lap(&JacobianTiming::relax_s);
    sim.download(to, v);
    lap(&JacobianTiming::readback_s);
    timing_.steps += steps;
    timing_.element_steps += double(steps) * double(n * K);
    timing_.most_column_steps = std::max(timing_.most_column_steps, steps);
    for (std::size_t k = 0; k < K; ++k) {
      ForwardSolution s;
      s.from_m = block(from, k, n);
      s.to_m = block(to, k, n);
      s.steps = steps;
      out.push_back(std::move(s));
    }
  }
  batch_wall_s_ += std::chrono::duration<double>(Clock::now() - start).count();
  return out;
}

}  // namespace vb
