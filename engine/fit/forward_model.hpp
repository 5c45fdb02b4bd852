#pragma once
/// The forward model of a fit: region moduli → the displacement of the posture change, solved to
/// static equilibrium with dynamic relaxation (docs/FIT.md, "Forward model").
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "engine/fit/fit_regions.hpp"
#include "engine/sim/element_setup.hpp"
#include "engine/sim/opencl_runtime.hpp"

namespace vb {

class Simulator;
struct UnloadedReferenceSimulators;

struct ForwardSolution {
  std::vector<double> from_m;  ///< n×3 equilibrium displacement in the `from` posture (m, world); zeros without one
  std::vector<double> to_m;    ///< n×3 equilibrium displacement in the scene's posture (m, world)
  /// unloaded reference state (fit.unloaded_reference): the rest offsets estimated with these
  /// moduli (n×3, m); empty otherwise
  std::vector<double> rest_offset_m;
  int reference_solves = 0;    ///< relaxation solves of its fixed point (0 without)
  std::int64_t steps = 0;      ///< relaxation steps of both postures
  /// the displacement of the posture change: to − from (n×3, m)
  std::vector<double> change_m() const;
};

/// Where the Jacobians' perturbed solves (solve_batch) spent their time, summed over this
/// object's calls: so a GPU run shows whether batching loses in setup, in steps or in read-back
/// (docs/FIT.md, "Batched solves"; summary.json `jacobian_timing`).
struct JacobianTiming {
  std::size_t jacobians = 0;   ///< solve_batch calls
  std::size_t columns = 0;     ///< perturbed solves
  std::size_t simulators = 0;  ///< simulators built for them: each is built once and kept (ForwardModel::solve)
  /// element arrays, tiling and Simulator construction (buffers, kernels, model upload), or the
  /// kept simulator's new moduli
  double setup_s = 0;
  double upload_s = 0;   ///< warm-start state uploads
  double relax_s = 0;    ///< relaxation steps with their convergence checks (both postures)
  double readback_s = 0; ///< the solutions' downloads
  std::int64_t steps = 0;      ///< relaxation steps launched (a batch's steps count once for all its copies)
  double element_steps = 0;    ///< Σ steps × elements relaxed: the work
  std::int64_t most_column_steps = 0;  ///< sequential: the most steps of one column; batched: of one batch

  /// One sequential solve's count: its steps over n elements, `built` simulators
  void add_solve(std::int64_t solve_steps, std::size_t n, std::size_t built) {
    simulators += built;
    steps += solve_steps;
    element_steps += double(solve_steps) * double(n);
    most_column_steps = std::max(most_column_steps, solve_steps);
  }
};

/// Adds the time since its previous lap (or its construction) to one phase of a JacobianTiming;
/// without one it only keeps time.
class PhaseLaps {
 public:
  explicit PhaseLaps(JacobianTiming* timing) : timing_(timing) {}
  void operator()(double JacobianTiming::*phase) {
    const auto now = std::chrono::steady_clock::now();
    if (timing_) timing_->*phase += std::chrono::duration<double>(now - mark_).count();
    mark_ = now;
  }
  void restart() { mark_ = std::chrono::steady_clock::now(); }  ///< the time since counts to no phase

 private:
  JacobianTiming* timing_;
  std::chrono::steady_clock::time_point mark_ = std::chrono::steady_clock::now();
};

class ForwardModel {
 public:
  /// Copies the scene and switches it to relaxation with the fit's tolerance. Tissues with fitted
  /// regions are split into one tissue per (tissue, region) unless regions are elements (then
  /// only linear and biphasic springs, whose per-element E the kernels read directly). Throws
  /// vb::Error without [gravity] or for more than 255 (tissue, region) pairs.
  ForwardModel(const Scene& scene, const Lattice& lattice, const FitRegions& regions, const FitSpec& fit,
               const ClContext& cl);
  ~ForwardModel();
  ForwardModel(const ForwardModel&) = delete;  // its simulator refers to its scene and lattice
  ForwardModel& operator=(const ForwardModel&) = delete;

  /// Solves both postures with these region moduli (Pa). `warm`: start from its states (fewer
  /// steps when the moduli changed little). Throws vb::Error when a posture does not reach
  /// equilibrium in fit.max_steps. One simulator serves every solve: built by the first, given
  /// each later solve's moduli (Simulator::set_materials), so a solve equals one on a simulator
  /// built for it (from the unloaded reference state: its two simulators, reference_forward.hpp).
  ForwardSolution solve(const std::vector<double>& region_modulus_pa, const ForwardSolution* warm = nullptr) const;

  /// Solves several sets of region moduli (each as solve(moduli[k], warm)) with the copies of the
  /// model side by side in one simulator, batch_size() copies at a time (docs/FIT.md, "Batched
  /// solves"; engine/fit/forward_batch.cpp). Each result equals its solve() to the equilibrium
  /// tolerance; every copy reports the batch's steps. A batch of K copies reuses the simulator of
  /// the last batch of K (new moduli only), as solve() does.
  std::vector<ForwardSolution> solve_batch(const std::vector<std::vector<double>>& moduli,
                                           const ForwardSolution* warm = nullptr) const;
  /// Copies per simulator: fit.batch = N (at most the 256 tissue ids allow), or 1 for auto (0) on
  /// every device (batches measured slower per Jacobian, docs/FIT.md); 1 with [volume] preserve or
  /// [reference_state] (their constraint and rest state are one per simulator).
  std::size_t batch_size() const;

  /// Every element's Young's modulus with these region moduli (n, Pa): the map the fit writes.
  std::vector<double> element_modulus(const std::vector<double>& region_modulus_pa) const;

  const FitRegions& regions() const { return regions_; }
  const Lattice& lattice() const { return split_ ? split_lattice_ : lattice_; }
  std::size_t forward_solves() const { return solves_; }
  /// wall time spent in solve_batch (the Jacobians' perturbed solves) by this object (s)
  double batch_wall_s() const { return batch_wall_s_; }
  /// its split into setup, uploads, relaxation and read-back, with the steps
  const JacobianTiming& jacobian_timing() const { return timing_; }
  /// whether solves start from the unloaded reference state (reference_forward.hpp)
  bool unloaded_reference() const { return unloaded_; }
  /// relaxation solves of the unloaded reference state's fixed point, over all forward solves
  std::size_t reference_solves() const { return reference_solves_; }

 private:
  ElementArrays arrays(const std::vector<double>& region_modulus_pa) const;
  /// solve(), its phases added to `timing` when given
  ForwardSolution solve_timed(const std::vector<double>& region_modulus_pa, const ForwardSolution* warm,
                              JacobianTiming* timing) const;

  mutable Scene scene_;  ///< relaxation; split tissues' moduli change per solve
  const Lattice& lattice_;
  const FitRegions& regions_;
  FitSpec fit_;
  const ClContext& cl_;
  bool split_ = false;
  bool unloaded_ = false;
  Lattice split_lattice_;
  /// split tissue → (region or −1, material name of the original tissue)
  std::vector<std::pair<std::int32_t, std::string>> split_origin_;
  ElementArrays base_;  ///< element path: the model's arrays
  std::vector<double> base_modulus_;  ///< n: E of each element's own material
  mutable std::size_t solves_ = 0;
  mutable double batch_wall_s_ = 0;
  mutable JacobianTiming timing_;
  mutable std::size_t reference_solves_ = 0;
  mutable std::unique_ptr<Simulator> sim_;  ///< solve()'s, built by the first solve
  /// solve()'s from the unloaded reference state (reference_forward.hpp), likewise
  mutable std::unique_ptr<UnloadedReferenceSimulators> reference_sims_;
  /// solve_batch's simulators by copies per batch (a Jacobian's full batches and its remainder),
  /// each with the tiled lattice it refers to; built by the first batch of that size
  struct BatchSimulator {
    std::unique_ptr<Lattice> lattice;
    std::unique_ptr<Simulator> sim;
  };
  mutable std::map<std::size_t, BatchSimulator> batch_sims_;
};

}  // namespace vb
