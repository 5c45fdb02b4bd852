#pragma once
/// One run of a scene, from the model to the files: what `simulate` does, and what `sweep` does
/// for each case.
#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "apps/image_outputs.hpp"
#include "apps/simulation_setup.hpp"
#include "engine/study/positioning_metrics.hpp"
#include "engine/sim/opencl_runtime.hpp"
#include "engine/sim/reference_state.hpp"
#include "engine/sim/run.hpp"

namespace vb::app {

struct SimulationOptions {
  /// true: summary.json, result.h5 and the image outputs and meshes the scene asks for;
  /// false: summary.json only (sweeps, where the numbers are what counts).
  bool full_outputs = true;
  /// The folder the outputs end up in when `out_dir` is a staging folder (RunFolder): an earlier
  /// series there must be VoxBreast's own before the run starts. Empty: `out_dir` itself.
  std::string final_dir;
  /// Called once the model is built and the simulator is ready, before the run.
  std::function<void(const PreparedModel&, const Simulator&)> on_start;
  std::function<void(const RunProgress&)> on_progress;
  /// [reference_state]: after each forward solve of the unloaded state's estimate
  std::function<void(const ReferenceIteration&)> on_reference_iteration;
  /// [reproducibility]: after each perturbed run
  std::function<void(const PerturbedRun&)> on_perturbed_run;
  /// A phase starts: "setup", "kernel build", "reference state", "solve", "reproducibility",
  /// "outputs". on_progress reports the steps of the reference state and reproducibility runs too.
  std::function<void(const std::string&)> on_phase;
  ImageOutputProgress on_image_progress;
  /// When the command started (unset: when simulate_scene was called): summary.json's
  /// wall_time_s is the time from here to its writing.
  std::optional<std::chrono::steady_clock::time_point> command_start;
};

/// Wall-clock seconds of each phase of a run (summary.json `timings`).
struct PhaseTimings {
  double setup_s = 0;            ///< scene checks, CT reading, classification, lattice
  double kernel_build_s = 0;     ///< the simulator: OpenCL programs, buffers, time step
  double reference_state_s = 0;  ///< [reference_state] solves
  double solve_s = 0;            ///< the run itself
  double reproducibility_s = 0;  ///< [reproducibility] runs
  double outputs_s = 0;          ///< metrics, result.h5, image outputs, meshes, summary
  double image_outputs_s = 0;    ///< of outputs_s: the DVFs, warped CT and maps on the CT grid
  double total_s = 0;            ///< the command, from SimulationOptions::command_start
};

struct SimulationReport {
  PositioningMetrics positioning;  ///< tumour, chest wall, device contact, comfort (docs/POSITIONING.md)
  RunSummary summary;
  std::vector<std::string> warnings;  ///< e.g. DICOM slice gaps accepted with allow_gaps
  /// Why the result is not a converged one (the run, the unloaded reference state, perturbed
  /// runs); each is among the warnings too. Empty: converged, or a fixed run as asked.
  std::vector<std::string> unconverged;
  bool image_outputs = false;         ///< DVF, warped CT and fields written (CT models)
  bool mesh_outputs = false;          ///< surface meshes and lattice written
  PhaseTimings timings;
};

class Progress;

/// Shows the run on `bar`: each phase by name (after `prefix`), each run's residual against the
/// equilibrium tolerance it stops at (the step count where the scene has none), the image outputs
/// by the fraction done. Sets on_phase, on_progress and on_image_progress.
void show_progress(Progress& bar, const Scene& scene, SimulationOptions& options, const std::string& prefix = "");

/// Builds the scene's model, runs it on `cl` and writes the outputs into `out_dir` (which must
/// exist), summary.json last. Safe to call from several threads at once, each with its own
/// context: the file readers and writers that are not thread-safe (HDF5, DCMTK) take turns.
SimulationReport simulate_scene(const Scene& scene, const ClContext& cl, const std::string& out_dir,
                                const SimulationOptions& options);

}  // namespace vb::app
