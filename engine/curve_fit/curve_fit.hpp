#pragma once
/// Fits material parameters of one tissue so that the scene's quasi-static press reproduces a
/// measured force–displacement curve (voxbreast fit-curve, docs/FIT_CURVE.md): Levenberg–Marquardt
/// (Eigen's MINPACK port) on forward-difference Jacobians, each evaluation a press curve
/// (engine/curve_fit/press_curve.hpp).
#include <functional>
#include <string>
#include <vector>

#include "engine/curve_fit/press_curve.hpp"

namespace vb {

/// A measured curve: the indenter's travel (m) and the force opposing it (N).
struct ForceCurve {
  std::vector<double> travel_m, force_n;
};

/// Rows (displacement_mm, force_n) → curve sorted by travel; throws vb::Error naming `source`
/// for a negative travel or one given twice.
ForceCurve force_curve_from_rows(const std::vector<std::vector<double>>& rows, const std::string& source);

struct CurveFitOptions {
  std::string tissue;                   ///< empty: the model's only tissue with a material
  std::vector<std::string> parameters;  ///< empty: the law's defaults (material_parameters.hpp)
  int points = 12;                      ///< press levels compared (evenly over the travel); 0: every measured one
  int max_evaluations = 120;            ///< press curves at most (Jacobian columns count)
  double step = 2e-3;                   ///< forward-difference step in the fit coordinates (~0.2%)
  PressCurveOptions press;
};

struct FitValue {
  std::string name;
  double start = 0, fitted = 0;
};

struct CurveFitResult {
  std::string tissue, law;
  std::vector<FitValue> parameters;
  std::vector<double> travel_m, measured_n, start_n, fitted_n;  ///< at the compared levels
  double start_rms_n = 0, rms_n = 0;  ///< RMS of simulated − measured over the levels (N)
  double relative_rms = 0;            ///< rms_n over the largest measured |force|
  double max_error_n = 0;
  int evaluations = 0, iterations = 0;
  std::string status;                 ///< why the optimiser stopped
};

/// `progress` (optional) hears of every evaluation: its count and the relative RMS.
CurveFitResult fit_force_curve(const Scene& scene, const Lattice& lattice, const ClContext& cl, const ForceCurve& curve,
                               const CurveFitOptions& options,
                               const std::function<void(int, double)>& progress = {});

}  // namespace vb
