#pragma once
/// One run of a scene, from the model to the files: what `simulate` does, and what `sweep` does
/// for each case.
#include <functional>
#include <string>
#include <vector>

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
};

/// Builds the scene's model, runs it on `cl` and writes the outputs into `out_dir` (which must
/// exist), summary.json last. Safe to call from several threads at once, each with its own
/// context: the file readers and writers that are not thread-safe (HDF5, DCMTK) take turns.
SimulationReport simulate_scene(const Scene& scene, const ClContext& cl, const std::string& out_dir,
                                const SimulationOptions& options);

}  // namespace vb::app
