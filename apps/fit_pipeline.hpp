#pragma once
/// One fit from a scene into a folder (docs/FIT.md, "Outputs"): model, observation, the chosen
/// method with a checkpoint per iteration, then the elasticity map, history, residual
/// statistics and summary.json. `voxbreast fit` runs it once or per case of a batch.
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "engine/fit/fit_progress.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/opencl_runtime.hpp"

namespace vb::app {

struct FitRunOptions {
  int stop_after_iterations = 0;  ///< stop (unfinished, resumable) after this many new iterations; 0: never
  bool plots = true;              ///< draw history.png with scripts/plot_fit.py
  /// a displacement field (NIfTI) of the true posture change: summary.json then also compares the
  /// fitted displacement with it ("truth"), for validation with a noisy observation
  std::string truth_path;
  /// called after every iteration with its history row
  std::function<void(const FitIteration&)> on_iteration;
};

/// Runs (or resumes, from DIR/checkpoint.json) the fit of the scene file's [fit] table into
/// `dir`. Returns summary.json's content; "finished" false when stopped by
/// stop_after_iterations. Throws vb::Error for bad inputs or a checkpoint of another fit.
nlohmann::json fit_scene(const Scene& scene, const ClContext& cl, const std::string& dir, const FitRunOptions& options);

/// Writes the displacement of the scene's posture change with the scene's own materials (the
/// ground truth of a validation) as a NIfTI displacement field on the lattice's grid, plus
/// Gaussian noise of `noise_m` per component (seeded). Returns the largest displacement (m).
double write_synthetic_observation(const Scene& scene, const ClContext& cl, const std::string& path, double noise_m,
                                   std::uint64_t seed);

/// Writes the model's tissues after the scene's posture change with its own materials as a label
/// map (the observation of a label-map fit's validation, fit.observed_labels): on a grid aligned
/// with the lattice, `subdivide` voxels per lattice spacing, input label values. Returns the
/// largest displacement (m).
double write_synthetic_labels(const Scene& scene, const ClContext& cl, const std::string& path, int subdivide);

/// Writes the boundary of one region (label value `label_value`: 0 the body outline, as
/// fit.observed_surface_values) after the scene's posture change with its own materials as a
/// binary STL (the observation of a surface-mesh fit's validation, fit.observed_surface): the
/// voxel faces of the region, their corners moved by the displacement interpolated there.
/// Returns the largest displacement (m).
double write_synthetic_surface(const Scene& scene, const ClContext& cl, const std::string& path, int label_value);

}  // namespace vb::app
