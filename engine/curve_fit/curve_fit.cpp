#include "engine/curve_fit/curve_fit.hpp"

#include <unsupported/Eigen/NonLinearOptimization>
#include <algorithm>
#include <cmath>
#include <map>

#include "engine/curve_fit/material_parameters.hpp"
#include "engine/error.hpp"
#include "engine/sim/element_setup.hpp"

namespace vb {
namespace {

const char* status_name(int status) {
  switch (status) {
    case Eigen::LevenbergMarquardtSpace::RelativeReductionTooSmall: return "converged: relative reduction below ftol";
    case Eigen::LevenbergMarquardtSpace::RelativeErrorTooSmall: return "converged: parameter change below xtol";
    case Eigen::LevenbergMarquardtSpace::RelativeErrorAndReductionTooSmall: return "converged: ftol and xtol";
    case Eigen::LevenbergMarquardtSpace::CosinusTooSmall: return "converged: gradient orthogonal to the residual";
    case Eigen::LevenbergMarquardtSpace::TooManyFunctionEvaluation: return "stopped: evaluation budget used";
    case Eigen::LevenbergMarquardtSpace::FtolTooSmall: return "stopped: no further reduction possible (ftol)";
    case Eigen::LevenbergMarquardtSpace::XtolTooSmall: return "stopped: no further improvement possible (xtol)";
    case Eigen::LevenbergMarquardtSpace::GtolTooSmall: return "stopped: gtol too small";
    default: return "stopped: improper input";
  }
}

double interpolate(const ForceCurve& c, double d) {
  const auto it = std::lower_bound(c.travel_m.begin(), c.travel_m.end(), d);
  if (it == c.travel_m.begin()) return c.force_n.front();
  if (it == c.travel_m.end()) return c.force_n.back();
  const std::size_t j = std::size_t(it - c.travel_m.begin());
  const double w = (d - c.travel_m[j - 1]) / (c.travel_m[j] - c.travel_m[j - 1]);
  return (1 - w) * c.force_n[j - 1] + w * c.force_n[j];
}

/// The model as a function of the fit coordinates x (x = 0 is the start): residuals
/// (simulated − measured)/F_scale at the levels. Remembers evaluated points (the optimiser asks
/// for the Jacobian where it just evaluated).
struct PressResiduals {
  using Scalar = double;
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };

  const Scene& scene;
  const Lattice& lattice;
  const ClContext& cl;
  const CurveFitOptions& options;
  std::string tissue;
  std::vector<std::string> names;
  std::vector<double> start_values, start_coordinates;
  std::vector<double> levels, measured;
  double scale = 1;
  const std::function<void(int, double)>& progress;
  mutable std::map<std::vector<double>, Eigen::VectorXd> cache;
  mutable int evaluations = 0;

  int inputs() const { return int(names.size()); }
  int values() const { return int(levels.size()); }

  Scene scene_at(const Eigen::VectorXd& x) const {
    Scene s = scene;
    MaterialSpec& m = s.materials.at(tissue);
    for (std::size_t j = 0; j < names.size(); ++j)
      set_parameter_value(m, names[j], from_coordinate(names[j], start_coordinates[j] + x[j], start_values[j]));
    return s;
  }

  std::vector<double> forces_at(const Eigen::VectorXd& x) const {
    const Scene s = scene_at(x);
    const ElementArrays el = make_element_arrays(s, lattice);
    return press_curve_forces(s, lattice, el, cl, levels, options.press);
  }

  /// Residuals; a trial the model cannot settle (a far step) gets a large misfit, so the
  /// optimiser shrinks its step instead of stopping.
  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& r) const {
    const std::vector<double> key(x.data(), x.data() + x.size());
    if (auto it = cache.find(key); it != cache.end()) {
      r = it->second;
      return 0;
    }
    r.resize(values());
    try {
      const std::vector<double> f = forces_at(x);
      for (int k = 0; k < values(); ++k) r[k] = (f[k] - measured[k]) / scale;
    } catch (const Error&) {
      r.setConstant(1e3);
    }
    ++evaluations;
    if (progress) progress(evaluations, r.norm() / std::sqrt(double(values())));
    cache[key] = r;
    return 0;
  }

  int df(const Eigen::VectorXd& x, Eigen::MatrixXd& J) const {
    Eigen::VectorXd r0, r1;
    (*this)(x, r0);
    J.resize(values(), inputs());
    for (int j = 0; j < inputs(); ++j) {
      Eigen::VectorXd xj = x;
      xj[j] += options.step;
      (*this)(xj, r1);
      J.col(j) = (r1 - r0) / options.step;
    }
    return inputs();  // function evaluations spent (the optimiser counts them)
  }
};

std::string only_tissue(const Scene& scene, const Lattice& lattice) {
  std::vector<std::string> candidates;
  for (const std::string& name : lattice.tissue_names)
    if (scene.materials.count(name) && !scene.materials.at(name).rigid) candidates.push_back(name);
  require(candidates.size() == 1, "the model has " + std::to_string(candidates.size()) + " soft tissues with a material",
          "--tissue", "name the tissue to fit");
  return candidates.front();
}

}  // namespace

ForceCurve force_curve_from_rows(const std::vector<std::vector<double>>& rows, const std::string& source) {
  std::vector<std::pair<double, double>> points;
  for (const auto& row : rows) {
    require(row.size() == 2, "a curve row has displacement_mm, force_n", source);
    require(row[0] >= 0, "displacement_mm " + std::to_string(row[0]) + " is negative", source,
            "displacements are the travel from first contact along the press");
    points.emplace_back(1e-3 * row[0], row[1]);
  }
  std::sort(points.begin(), points.end());
  ForceCurve c;
  for (const auto& [d, f] : points) {
    require(c.travel_m.empty() || d > c.travel_m.back(),
            "displacement " + std::to_string(1e3 * d) + " mm is given twice", source, "average repeated samples first");
    c.travel_m.push_back(d);
    c.force_n.push_back(f);
  }
  require(c.travel_m.size() >= 2 && c.travel_m.back() > 0, "the curve needs at least two displacements", source);
  return c;
}

CurveFitResult fit_force_curve(const Scene& scene, const Lattice& lattice, const ClContext& cl, const ForceCurve& curve,
                               const CurveFitOptions& o, const std::function<void(int, double)>& progress) {
  CurveFitResult result;
  result.tissue = o.tissue.empty() ? only_tissue(scene, lattice) : o.tissue;
  require(scene.materials.count(result.tissue) > 0, "no material '" + result.tissue + "' in the scene", "--tissue");
  const MaterialSpec& material = scene.materials.at(result.tissue);
  result.law = material.law;
  const std::vector<std::string> names = o.parameters.empty() ? default_fit_parameters(material) : o.parameters;
  for (const std::string& name : names) check_fit_parameter(material, name);

  std::vector<double> levels;
  if (o.points > 0) {
    for (int k = 1; k <= o.points; ++k) levels.push_back(curve.travel_m.back() * k / o.points);
    levels.erase(std::remove_if(levels.begin(), levels.end(), [&](double d) { return d < curve.travel_m.front(); }),
                 levels.end());
  } else {
    for (double d : curve.travel_m)
      if (d > 0) levels.push_back(d);
  }
  require(levels.size() >= names.size(), "the curve gives " + std::to_string(levels.size()) +
              " press levels for " + std::to_string(names.size()) + " parameters", "--points",
          "compare more levels or fit fewer parameters");

  PressResiduals f{scene, lattice, cl, o, result.tissue, names, {}, {}, levels, {}, 1.0, progress, {}, 0};
  for (const std::string& name : names) {
    f.start_values.push_back(parameter_value(material, name));
    f.start_coordinates.push_back(to_coordinate(name, f.start_values.back()));
  }
  for (double d : levels) f.measured.push_back(interpolate(curve, d));
  f.scale = 0;
  for (double m : f.measured) f.scale = std::max(f.scale, std::abs(m));
  require(f.scale > 0, "the measured forces are all zero", "curve");

  Eigen::VectorXd x = Eigen::VectorXd::Zero(f.inputs());
  result.start_n = f.forces_at(x);  // the start must work: errors here are the user's to see
  Eigen::LevenbergMarquardt<PressResiduals> lm(f);
  lm.parameters.maxfev = o.max_evaluations;
  lm.parameters.xtol = 1e-5;
  lm.parameters.ftol = 1e-8;
  lm.parameters.factor = 1;  // first step at most about e (×2.7) in any parameter
  const int status = lm.minimize(x);

  const Scene fitted = f.scene_at(x);
  for (std::size_t j = 0; j < names.size(); ++j)
    result.parameters.push_back({names[j], f.start_values[j], parameter_value(fitted.materials.at(result.tissue), names[j])});
  result.fitted_n = f.forces_at(x);
  result.travel_m = levels;
  result.measured_n = f.measured;
  double sum_start = 0, sum = 0;
  for (std::size_t k = 0; k < levels.size(); ++k) {
    const double e = result.fitted_n[k] - f.measured[k], e0 = result.start_n[k] - f.measured[k];
    sum += e * e, sum_start += e0 * e0;
    result.max_error_n = std::max(result.max_error_n, std::abs(e));
  }
  result.rms_n = std::sqrt(sum / double(levels.size()));
  result.start_rms_n = std::sqrt(sum_start / double(levels.size()));
  result.relative_rms = result.rms_n / f.scale;
  result.evaluations = f.evaluations + 2;
  result.iterations = int(lm.iter);
  result.status = status_name(status);
  return result;
}

}  // namespace vb
