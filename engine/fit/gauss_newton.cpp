#include "engine/fit/gauss_newton.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "engine/error.hpp"

namespace vb {
namespace {

using Clock = std::chrono::steady_clock;

/// Counters that carry over from earlier runs of a resumed fit.
struct RunClock {
  Clock::time_point start = Clock::now();
  std::int64_t earlier_solves = 0;
  double earlier_wall_s = 0;
  std::size_t solves_at_start = 0;
  RunClock(const FitProgress& p, const ForwardModel& m) : solves_at_start(m.forward_solves()) {
    if (!p.history.empty()) {
      earlier_solves = p.history.back().forward_solves;
      earlier_wall_s = p.history.back().wall_time_s;
    }
  }
  void stamp(FitIteration& row, const ForwardModel& m) const {
    row.forward_solves = earlier_solves + std::int64_t(m.forward_solves() - solves_at_start);
    row.wall_time_s = earlier_wall_s + std::chrono::duration<double>(Clock::now() - start).count();
  }
};

/// Weighted residual rows sqrt(w/N)·(sim − obs) of any kind of observation: N observed points.
Eigen::VectorXd data_residual(const FitData& data, const std::vector<double>& change_m) {
  const ResidualRows rows = data.rows(change_m);
  const double N = double(std::max<std::size_t>(1, data.points()));
  return (rows.weight_per_m2.array() / N).sqrt() * rows.value_m.array();
}

double data_points(const FitData& data) { return double(std::max<std::size_t>(1, data.points())); }

/// The Cramér–Rao standard errors of ln E: J holds the rows sqrt(w/N)·∂d/∂θ, so the Fisher
/// information of noise with the rows' σ (w = 1/σ²) is N·JᵀJ; the bound is its inverse's diagonal.
std::vector<double> cramer_rao_log_se(const Eigen::MatrixXd& J, double N) {
  const Eigen::MatrixXd fisher = N * (J.transpose() * J);
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(fisher);
  std::vector<double> se(std::size_t(J.cols()), std::numeric_limits<double>::infinity());
  if (!lu.isInvertible()) return se;
  const Eigen::MatrixXd cov = lu.inverse();
  for (Eigen::Index r = 0; r < J.cols(); ++r) se[std::size_t(r)] = cov(r, r) > 0 ? std::sqrt(cov(r, r)) : se[std::size_t(r)];
  return se;
}

double regularisation_cost(const FitProblem& p, const std::vector<double>& E) {
  double sum = 0;
  for (std::size_t r = 0; r < E.size(); ++r) sum += std::pow(std::log(E[r] / p.initial_pa[r]), 2);
  return p.spec.regularisation * sum;
}

void finish(FitProgress& progress, const std::string& reason, const FitCheckpoint& checkpoint) {
  progress.finished = true;
  progress.stop_reason = reason;
  if (checkpoint) checkpoint(progress);
}

}  // namespace

FitIteration evaluate_fit(const FitProblem& p, const std::vector<double>& change_m, const std::vector<double>& E) {
  FitIteration row;
  row.data_cost = data_residual(*p.data, change_m).squaredNorm();
  row.cost = row.data_cost + regularisation_cost(p, E);
  const ResidualStats s = p.data->stats(change_m);
  row.rms_mm = s.rms_m * 1e3;
  row.within_1mm = s.within_1mm;
  row.max_mm = s.max_m * 1e3;
  row.modulus_pa = E;
  return row;
}

FitProgress run_gauss_newton(const FitProblem& p, FitProgress progress, const FitCheckpoint& checkpoint) {
  require(p.model != nullptr && p.data != nullptr, "a fit needs a forward model and observed data", "fit");
  const ForwardModel& model = *p.model;
  const std::size_t R = p.initial_pa.size();
  require(R <= 512, std::to_string(R) + " regions is too many for a Jacobian by perturbed solves", "fit.regions",
          "use method = \"bisection\", larger blocks, or labels");
  const RunClock clock(progress, model);
  const double lo = std::log(p.min_pa), hi = std::log(p.max_pa);
  if (progress.history.empty()) progress.modulus_pa = p.initial_pa;
  std::vector<double> E = progress.modulus_pa;
  ForwardSolution base;
  if (progress.state_to_m.empty()) {
    base = model.solve(E);
  } else {  // resumed: the accepted solution of the last iteration
    base.from_m = progress.state_from_m;
    base.to_m = progress.state_to_m;
    base.rest_offset_m = progress.state_rest_m;
  }
  const auto keep_state = [&] {
    progress.state_from_m = base.from_m;
    progress.state_to_m = base.to_m;
    progress.state_rest_m = base.rest_offset_m;
  };
  keep_state();
  FitIteration current = evaluate_fit(p, base.change_m(), E);
  if (progress.history.empty()) {
    current.iteration = 0;
    current.lm_damping = progress.lm_damping;
    clock.stamp(current, model);
    progress.history.push_back(current);
    if (checkpoint) checkpoint(progress);
  }
  double mu = progress.lm_damping;
  const double alpha = p.spec.regularisation;
  while (int(progress.history.size()) <= p.spec.max_iterations) {
    // Jacobian of the weighted residual by one-sided perturbed solves in log E, solved together
    // (ForwardModel::solve_batch).
    const Eigen::VectorXd r0 = data_residual(*p.data, base.change_m());
    Eigen::MatrixXd J(r0.size(), Eigen::Index(R));
    std::vector<std::vector<double>> perturbed(R, E);
    std::vector<double> h(R);
    for (std::size_t k = 0; k < R; ++k) {
      h[k] = std::log(E[k]) + p.spec.step_log > hi ? -p.spec.step_log : p.spec.step_log;
      perturbed[k][k] = E[k] * std::exp(h[k]);
    }
    const std::vector<ForwardSolution> columns = model.solve_batch(perturbed, &base);
    for (std::size_t k = 0; k < R; ++k)
      J.col(Eigen::Index(k)) = (data_residual(*p.data, columns[k].change_m()) - r0) / h[k];
    progress.log_standard_error = cramer_rao_log_se(J, data_points(*p.data));
    Eigen::VectorXd theta(static_cast<Eigen::Index>(R)), theta0(static_cast<Eigen::Index>(R));
    for (std::size_t k = 0; k < R; ++k) theta[Eigen::Index(k)] = std::log(E[k]), theta0[Eigen::Index(k)] = std::log(p.initial_pa[k]);
    const Eigen::MatrixXd H = J.transpose() * J + alpha * Eigen::MatrixXd::Identity(Eigen::Index(R), Eigen::Index(R));
    const Eigen::VectorXd g = J.transpose() * r0 + alpha * (theta - theta0);

    bool accepted = false;
    double step_norm = 0;
    for (int attempt = 0; attempt < 8 && !accepted; ++attempt) {
      Eigen::MatrixXd A = H;
      A.diagonal() += mu * H.diagonal();
      const Eigen::VectorXd delta = -A.ldlt().solve(g);
      std::vector<double> trial(R);
      step_norm = 0;
      for (std::size_t k = 0; k < R; ++k) {
        const double t = std::clamp(theta[Eigen::Index(k)] + delta[Eigen::Index(k)], lo, hi);
        step_norm = std::max(step_norm, std::abs(t - theta[Eigen::Index(k)]));
        trial[k] = std::exp(t);
      }
      if (step_norm < 1e-6) break;
      ForwardSolution st = model.solve(trial, &base);
      const FitIteration row = evaluate_fit(p, st.change_m(), trial);
      if (row.cost < current.cost) {
        accepted = true;
        const double decrease = (current.cost - row.cost) / std::max(current.cost, 1e-300);
        mu = std::max(mu / 3, 1e-7);
        E = trial;
        base = std::move(st);
        current = row;
        current.iteration = int(progress.history.size());
        current.lm_damping = mu;
        clock.stamp(current, model);
        progress.history.push_back(current);
        progress.modulus_pa = E;
        progress.lm_damping = mu;
        keep_state();
        if (decrease < p.spec.tolerance) {
          finish(progress, "cost fell by less than fit.tolerance", checkpoint);
          return progress;
        }
        if (checkpoint) checkpoint(progress);
      } else {
        mu *= 4;
      }
    }
    if (!accepted) {
      progress.lm_damping = mu;
      finish(progress, step_norm < 1e-6 ? "step vanished (at a bound or a minimum)" : "no step lowers the cost",
             checkpoint);
      return progress;
    }
  }
  finish(progress, "fit.max_iterations reached", checkpoint);
  return progress;
}

FitProgress run_bisection(const FitProblem& p, FitProgress progress, const FitCheckpoint& checkpoint) {
  const ForwardModel& model = *p.model;
  require(p.observation != nullptr, "the bisection compares displacement magnitudes: it needs a displacement observation",
          "fit.method", "use method = \"gauss-newton\" with fit.observed_labels");
  const Observation& obs = *p.observation;
  const std::size_t R = p.initial_pa.size();
  const RunClock clock(progress, model);
  if (progress.history.empty()) {
    progress.modulus_pa = p.initial_pa;
    progress.lower_log.assign(R, std::log(p.min_pa));
    progress.upper_log.assign(R, std::log(p.max_pa));
  }
  const std::vector<std::int32_t>& region = model.regions().region_of_element;
  ForwardSolution last;
  last.from_m = progress.state_from_m;
  last.to_m = progress.state_to_m;
  last.rest_offset_m = progress.state_rest_m;
  bool have_last = !last.to_m.empty();
  // progress.modulus_pa is always the next state to evaluate; history holds evaluated ones.
  for (;;) {
    ForwardSolution s = model.solve(progress.modulus_pa, have_last ? &last : nullptr);
    const std::vector<double> d = s.change_m();
    FitIteration row = evaluate_fit(p, d, progress.modulus_pa);
    row.iteration = int(progress.history.size());
    clock.stamp(row, model);
    progress.history.push_back(row);
    last = std::move(s);
    have_last = true;
    if (int(progress.history.size()) > p.spec.max_iterations) break;
    // Per region: does it move more (too soft) or less (too stiff) than observed?
    std::vector<double> excess(R, 0.0), weight(R, 0.0);
    for (std::size_t e = 0; e < obs.weight_per_m2.size(); ++e) {
      if (region[e] < 0 || obs.weight_per_m2[e] <= 0) continue;
      const double sim = std::hypot(d[3 * e], d[3 * e + 1], d[3 * e + 2]);
      const double ob = std::hypot(obs.displacement_m[3 * e], obs.displacement_m[3 * e + 1], obs.displacement_m[3 * e + 2]);
      excess[std::size_t(region[e])] += obs.weight_per_m2[e] * (sim - ob);
      weight[std::size_t(region[e])] += obs.weight_per_m2[e];
    }
    double widest = 0;
    for (std::size_t r = 0; r < R; ++r) {
      if (weight[r] == 0) continue;  // unobserved region: keeps its guess
      const double t = std::log(progress.modulus_pa[r]);
      if (excess[r] > 0) progress.lower_log[r] = t;
      else progress.upper_log[r] = t;
      progress.modulus_pa[r] = std::exp(0.5 * (progress.lower_log[r] + progress.upper_log[r]));
      widest = std::max(widest, progress.upper_log[r] - progress.lower_log[r]);
    }
    if (widest < 1e-3) {
      progress.modulus_pa = progress.history.back().modulus_pa;
      finish(progress, "every bracket narrower than 0.1%", checkpoint);
      return progress;
    }
    progress.state_from_m = last.from_m;
    progress.state_to_m = last.to_m;
    progress.state_rest_m = last.rest_offset_m;
    if (checkpoint) checkpoint(progress);
  }
  progress.modulus_pa = progress.history.back().modulus_pa;
  finish(progress, "fit.max_iterations reached", checkpoint);
  return progress;
}

}  // namespace vb
