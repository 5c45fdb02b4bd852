#pragma once
/// Which knob combinations `voxbreast bench` runs: the full law × integrator × precision grid at
/// the base resolution and step, plus one-factor-at-a-time (OFAT) sweeps of resolution, time step
/// and the volume constraint around each base case (docs/BENCHMARKS.md, "Design").
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"

namespace vb::bench {

/// One combination of knobs on one scene.
struct BenchCase {
  std::string scene;
  std::string law = "linear";
  std::string integrator = "heun";
  Precision precision = Precision::Float;
  int downsample = 1;     ///< merge downsample³ finest voxels into one element
  double dt_factor = 1;   ///< × the automatic step
  bool volume = false;    ///< [volume] preserve
  double tolerance = 0;   ///< stop.equilibrium; 0: the scene's
  /// which part of the design asked for it: "reference", "base", "grid", "resolution",
  /// "time_step", "volume", "tolerance"
  std::string part;

  /// The knobs as one string (a case is run once however many parts ask for it).
  std::string knobs() const;
  /// The scene whose reference solution this case is compared with: scene, law and volume.
  std::string reference_key() const;
};

struct DesignSpec {
  std::vector<std::string> laws, integrators;  ///< the grid
  std::vector<Precision> precisions;
  std::vector<std::string> base_laws;          ///< OFAT sweeps run around each of these
  std::string base_integrator = "heun";
  Precision base_precision = Precision::Float;
  std::vector<int> downsamples;                ///< resolution levels; the first is the base
  std::vector<double> dt_factors;              ///< 1 is the base
  bool volume = true;                          ///< sweep the volume constraint
  /// equilibrium tolerances swept in both precisions (where float's round-off floor shows)
  std::vector<double> tolerances;
};

/// The cases for one scene, in run order, each knob combination once.
std::vector<BenchCase> make_design(const std::string& scene, const DesignSpec& spec);

/// The reference of a case: finest resolution, double precision, Heun, `dt_factor` × the
/// automatic step, equilibrium `tolerance`; same scene, law and volume constraint.
BenchCase reference_case(const BenchCase& c, double dt_factor, double tolerance);

}  // namespace vb::bench
