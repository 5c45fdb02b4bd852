#pragma once
/// Throughput part of `voxbreast bench`: steps/s of cube models of given sizes, as a fraction of
/// the device's copy bandwidth measured in the same run (docs/BENCHMARKS.md, "Throughput").
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"
#include "engine/sim/launch_plan.hpp"
#include "engine/sim/opencl_runtime.hpp"

namespace vb::app {

struct ThroughputOptions {
  std::vector<int> sizes;                   ///< block edge lengths in elements
  std::vector<std::string> laws{"linear"};  ///< laws timed with Heun + float
  bool quick = false;                       ///< 0.5 s per timing, Heun + float only
  bool volume = false;   ///< also time each law with [volume] preserve = true (model "block_volume")
  VolumeSpec::Predictor volume_predictor = VolumeSpec::Predictor::Pressure;  ///< [volume] predictor of those
  bool profile = false;  ///< print device time per kernel (a second, profiling run of each block)
  double cube_dashpot_ratio = SolverSpec{}.dashpot_ratio;  ///< the cubes' dashpots ζ (0: global damping only)
  std::string phantom_scene;  ///< the breast phantom's scene.toml, for the two options below
  /// also time the phantom resampled to ~36k elements (models "breast", "breast_volume"), every law
  bool breast = false;
  bool breast_large = false;  ///< also time it at ~1.5M elements (model "breast_large"), linear springs
  /// also time it resampled to about each of these element counts (model "breast_resampled"),
  /// each law and integrator: the phantom's rate against size (where the step list and the
  /// one-launch step pay, docs/PERFORMANCE.md, "Launches per step")
  std::vector<long> breast_elements;
  std::vector<std::string> breast_integrators{"heun"};  ///< those models' integrators (bench knob names)
  PlanOverrides plan;  ///< launch-plan overrides of every timed model (--plan)
};

struct ThroughputResult {
  double copy_bandwidth_gb_s = 0;
  nlohmann::json rows = nlohmann::json::array();
  std::string csv;  ///< throughput.csv
};

/// Times every model; prints one line per model.
ThroughputResult run_throughput(const ClContext& cl, const ThroughputOptions& options);

}  // namespace vb::app
