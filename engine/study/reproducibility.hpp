#pragma once
/// Reproducibility of a positioning ([reproducibility], docs/POSITIONING.md): the scene run again
/// under N random small posture changes — roll, pitch and yaw of the chest-wall sphere anchor,
/// each uniform in [−θ, θ] — with its device and, with the same angles, without it. The spread
/// of the tumour centroid over the N runs says how well the device holds the tumour in place.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "engine/sim/opencl_runtime.hpp"
#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/run.hpp"

namespace vb {

/// The N perturbations (roll, pitch, yaw in degrees) of a seed: the same on every machine (the
/// raw output of std::mt19937_64, whose sequence the C++ standard fixes).
std::vector<Vec3> perturbation_angles_deg(const ReproducibilitySpec& spec);

struct PerturbedRun {
  int index = 0;                ///< 1-based perturbation
  bool device = false;          ///< with the scene's [[device.torus]]
  Vec3 rpy_deg = Vec3::Zero();  ///< added to the chest-wall anchor's pose
  Vec3 tumour_centroid_m = Vec3::Zero();
  bool converged = false;
  std::int64_t steps = 0;
};

/// Spread of the tumour centroid over the runs of one configuration.
struct TumourSpread {
  int runs = 0;
  Vec3 mean_m = Vec3::Zero();
  Vec3 std_axis_m = Vec3::Zero();  ///< per axis (population std)
  double std_m = 0;                ///< √(mean |p − p̄|²): the 3-D RMS distance from the mean
  double max_m = 0;                ///< largest |p − p̄|
};

struct ReproducibilityResult {
  std::vector<PerturbedRun> runs;
  std::optional<TumourSpread> with_device;  ///< scenes with a device only
  TumourSpread without_device;
};

/// The spread of a set of centroids (none: all zero).
TumourSpread tumour_spread(const std::vector<Vec3>& centroids_m);

/// A warning naming the runs that stopped without equilibrium, whose centroids the spreads still
/// count, or nothing when every run settled.
std::optional<std::string> unsettled_runs_warning(const ReproducibilityResult& result);

/// Runs the perturbations on `cl`: each is the scene's run from the CT (same integrator, stop
/// rule and, when given, the same unloaded rest offsets) with the chest-wall anchor turned.
/// Throws vb::Error when the scene has no tumour tissue or no sphere chest-wall anchor, or a run
/// goes unstable; a run that stops without equilibrium is kept and marked. `on_run` is called
/// after each run, `on_step` at each equilibrium check of a run.
ReproducibilityResult run_reproducibility(const Scene& scene, const Lattice& lattice, const ClContext& cl,
                                          const std::vector<double>* rest_offsets_m,
                                          const std::function<void(const PerturbedRun&)>& on_run = {},
                                          const std::function<void(const RunProgress&)>& on_step = {});

}  // namespace vb
