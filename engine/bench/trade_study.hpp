#pragma once
/// Runs bench cases to equilibrium and measures each against the reference solution of its
/// scene: the finest, double-precision, small-step run, computed once per scene, law and volume
/// constraint (docs/BENCHMARKS.md, "Reference and error measures").
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "engine/bench/bench_design.hpp"
#include "engine/bench/bench_scenes.hpp"
#include "engine/sim/element_setup.hpp"
#include "engine/sim/opencl_runtime.hpp"

namespace vb::bench {

struct CaseResult {
  BenchCase knobs;
  /// "ok" (reached equilibrium), "not_converged" (not within the step or time cap), "unstable"
  /// (blew up: the run's instability error is in `message`), "failed" (any other error, in
  /// `message`)
  std::string status;
  std::string message;
  std::size_t elements = 0;
  double spacing_m = 0;
  double dt_s = 0;
  double auto_dt_s = 0;                  ///< the automatic step (dt = dt_factor × this)
  std::int64_t steps = 0;                ///< to equilibrium (or until stopped)
  double simulated_s = 0;                ///< simulated time of those steps (s)
  double wall_s = 0;                     ///< wall time of those steps, checks included (s)
  double tolerance = 0;                  ///< the stop.equilibrium it ran to
  double seconds_per_step = 0;
  double device_bytes_per_element = 0;
  static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  double max_displacement_m = nan;       ///< largest element displacement of this run (m)
  // Against the reference (NaN when this run or the reference has no result):
  double error_max_m = nan;              ///< max |u − u_ref| over the reference's free elements (m)
  double error_rms_m = nan;              ///< RMS of the same (m)
  double track_error_m = nan;            ///< largest |u − u_ref| at the scene's tracked points (m)
  double volume_change = nan;            ///< (V − V0)/V0 of the surface-enclosed volume (fraction)
  double volume_error = nan;             ///< |volume_change − that of the reference| (fraction)
  /// column only: top-layer mean sag / closed-form sag − 1 (fraction)
  double closed_form_error = nan;
};

struct StudySettings {
  /// The reference's step: at equilibrium the step does not enter the balance of forces, so a
  /// smaller one changes the path, not the result; the tolerance and double precision make it exact.
  double reference_dt_factor = 0.5;
  /// A reference runs to this fraction of the tightest tolerance of the cases compared with it,
  /// so that its own distance from equilibrium is ~1% of theirs.
  double reference_tolerance_factor = 0.01;
  std::int64_t reference_max_steps = 2000000;
  std::int64_t max_steps = 200000;           ///< cap on every other run
  /// every other run stops as not converged after this many times its reference's simulated time
  double max_time_over_reference = 3;
};

class TradeStudy {
 public:
  TradeStudy(const ClContext& cl, const StudySettings& settings) : cl_(cl), settings_(settings) {}
  void add_scene(BenchScene scene);
  /// Announces a case that will run: references run to `reference_tolerance_factor` × the
  /// tightest tolerance among the cases announced for them.
  void expect(const BenchCase& c);
  const BenchScene& scene(const std::string& name) const;

  /// Runs the case; first its reference when that has not been run yet. Returns the new rows:
  /// the reference (when run now) and the case. A reference case itself returns its row again.
  std::vector<CaseResult> run(const BenchCase& c);

 private:
  struct Reference {
    CaseResult result;
    std::vector<Eigen::Vector3d> points_m;  ///< rest positions of the free elements (m)
    std::vector<Eigen::Vector3d> u_m;       ///< their displacements (m)
    std::vector<Eigen::Vector3d> track_u_m; ///< displacement at the scene's tracked points (m)
  };
  struct Outcome {
    CaseResult result;
    Lattice lattice;
    ElementArrays elements;
    std::vector<double> u_m;  ///< final displacement (n×3, m); empty when the run has none
  };
  /// Builds the case's model and runs it to equilibrium; a run that fails is a row, not a throw.
  Outcome simulate(const BenchCase& c, std::int64_t max_steps, double max_time_s) const;
  const Reference& reference(const BenchCase& c, std::vector<CaseResult>& new_rows);
  /// Fills the error columns of a run that has a result, against a reference that has one.
  void measure(CaseResult& r, const Outcome& o, const Reference& ref) const;

  const ClContext& cl_;
  StudySettings settings_;
  std::map<std::string, BenchScene> scenes_;
  std::map<std::string, Reference> references_;
  std::map<std::string, double> tightest_tolerance_;  ///< by reference key
};

}  // namespace vb::bench
