#pragma once
/// The state of a fit between iterations: what a checkpoint stores so a killed fit resumes
/// without redoing iterations (docs/FIT.md, "Outputs").
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace vb {

struct FitIteration {
  int iteration = 0;           ///< 0: the initial guess
  double cost = 0;             ///< data + regularisation
  double data_cost = 0;        ///< mean over observed elements of Σ_xyz ((sim − obs)/σ)²
  double rms_mm = 0;           ///< RMS of |sim − obs| over observed elements (mm)
  double within_1mm = 0;       ///< fraction of observed elements with |sim − obs| ≤ 1 mm
  double max_mm = 0;           ///< largest |sim − obs| (surface observations: |surface distance|)
  double lm_damping = 0;       ///< Levenberg-Marquardt μ after this iteration (Gauss-Newton)
  std::int64_t forward_solves = 0;  ///< since the start of the fit (all runs)
  double wall_time_s = 0;           ///< since the start of the fit (all runs)
  std::vector<double> modulus_pa;   ///< per region after this iteration
};

struct FitProgress {
  std::vector<double> modulus_pa;          ///< current per-region moduli (Pa)
  std::vector<double> lower_log, upper_log;  ///< bisection: each region's bracket (ln Pa)
  double lm_damping = 1e-3;
  /// The forward solution the next iteration starts from (n×3 each, m): saved so a resumed fit
  /// continues exactly as an uninterrupted one would (empty: solve afresh).
  std::vector<double> state_from_m, state_to_m;
  std::vector<double> state_rest_m;  ///< its rest offsets (fit.unloaded_reference; else empty)
  std::vector<FitIteration> history;
  /// Cramér–Rao bound of each region's ln E from the last Jacobian (Gauss-Newton): the standard
  /// error √[(Σ_rows w ∂d/∂θ ∂d/∂θᵀ)⁻¹]_rr with noise of the fit's σ; +inf where the data do not
  /// determine the region (singular information); empty before the first Jacobian
  std::vector<double> log_standard_error;
  bool finished = false;
  std::string stop_reason;
};

/// Called after every iteration (and at the end) with the state to save.
using FitCheckpoint = std::function<void(const FitProgress&)>;

}  // namespace vb
