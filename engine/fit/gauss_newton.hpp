#pragma once
/// Levenberg-Marquardt (damped Gauss-Newton) in log E with Tikhonov regularisation towards the
/// initial guess, the Jacobian from perturbed forward solves (docs/FIT.md, "Method").
#include "engine/fit/fit_data.hpp"
#include "engine/fit/fit_progress.hpp"
#include "engine/fit/forward_model.hpp"
#include "engine/fit/observation.hpp"

namespace vb {

struct FitProblem {
  const ForwardModel* model = nullptr;
  const FitData* data = nullptr;            ///< what the cost compares (displacements or surfaces)
  const Observation* observation = nullptr; ///< displacement observations (the bisection needs them)
  std::vector<double> initial_pa;           ///< per region
  double min_pa = 0, max_pa = 0;            ///< bounds
  FitSpec spec;
};

/// Continues `progress` (empty history: a new fit) until the cost stops falling, the step
/// vanishes or fit.max_iterations is reached; calls `checkpoint` after every iteration.
FitProgress run_gauss_newton(const FitProblem& problem, FitProgress progress, const FitCheckpoint& checkpoint);

/// The paper's per-region iterative binary search (section 4.1 of the source paper): each
/// region's modulus is bisected in log E between the bounds, upwards where the simulated
/// displacement magnitude exceeds the observed one on its elements, downwards otherwise. One
/// forward solve per iteration.
FitProgress run_bisection(const FitProblem& problem, FitProgress progress, const FitCheckpoint& checkpoint);

/// cost terms of a forward solution: data (as FitIteration::data_cost) and the fields of the row
FitIteration evaluate_fit(const FitProblem& problem, const std::vector<double>& change_m,
                          const std::vector<double>& modulus_pa);

}  // namespace vb
