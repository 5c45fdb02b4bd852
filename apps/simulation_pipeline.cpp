#include "apps/simulation_pipeline.hpp"

#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>

#include "apps/device_mesh_outputs.hpp"
#include "engine/error.hpp"
#include "apps/image_outputs.hpp"
#include "apps/mesh_outputs.hpp"
#include "apps/progress.hpp"
#include "io/atomic_file.hpp"
#include "io/csv_table.hpp"
#include "io/dicom_io.hpp"
#include "io/hdf5_result.hpp"
#include "io/json_summary.hpp"
#include "io/metrics_csv.hpp"

namespace vb::app {
namespace {

/// Held while reading inputs and writing outputs: Debian's HDF5 is built without thread safety.
std::mutex& file_io_mutex() {
  static std::mutex mutex;
  return mutex;
}

/// reproducibility.csv: one row per perturbed run (angles in degrees, centroid in mm).
void write_reproducibility_csv(const std::string& path, const ReproducibilityResult& r) {
  std::string text = csv_line({"run", "device", "roll_deg", "pitch_deg", "yaw_deg", "tumour_x_mm", "tumour_y_mm",
                               "tumour_z_mm", "converged", "steps"});
  for (const PerturbedRun& p : r.runs) {
    std::vector<std::string> row = {std::to_string(p.index), p.device ? "1" : "0"};
    for (int c = 0; c < 3; ++c) row.push_back(shortest_number_text(p.rpy_deg[c]));
    for (int c = 0; c < 3; ++c) row.push_back(shortest_number_text(1e3 * p.tumour_centroid_m[c]));
    row.push_back(p.converged ? "1" : "0");
    row.push_back(std::to_string(p.steps));
    text += csv_line(row);
  }
  write_text_atomically(path, text);
}

}  // namespace

void show_progress(Progress& bar, const Scene& scene, SimulationOptions& options, const std::string& prefix) {
  // Each run ends at its equilibrium tolerance: the reference state's solves at their own.
  auto tolerance = std::make_shared<double>(scene.stop.equilibrium);
  options.on_phase = [&bar, &scene, tolerance, prefix](const std::string& phase) {
    bar.phase(prefix + phase);
    *tolerance = phase == "reference state" ? reference_state_scene(scene).stop.equilibrium : scene.stop.equilibrium;
  };
  // A dynamic run stops when both its residual and its speed are within the tolerance, so the
  // larger of the two is what converges; relaxation's speed test is another scale (engine/sim/run.cpp),
  // so there the residual alone is shown.
  const bool both = scene.solver.integrator != Integrator::Relaxation;
  options.on_progress = [&bar, tolerance, both](const RunProgress& p) {
    char text[160];
    std::snprintf(text, sizeof text, "step %lld  t=%.4g s  residual %.2e  speed %.2e", (long long)p.step, p.time_s,
                  p.residual, p.speed_ratio);
    if (*tolerance > 0) bar.converge(both ? std::max(p.residual, p.speed_ratio) : p.residual, *tolerance, text);
    else bar.update(double(p.step) / double(p.max_steps), text);  // no equilibrium rule: the step limit ends the run
  };
  options.on_image_progress = [&bar](const std::string& what, double fraction) { bar.update(fraction, what); };
}

SimulationReport simulate_scene(const Scene& scene, const ClContext& cl, const std::string& out_dir,
                                const SimulationOptions& options) {
  // The [probe] indenter may have no start: only voxbreast probe places it.
  require(!scene.probe.active || scene.indenters[scene.probe.indenter].has_start,
          "the [probe] indenter has no start, so only 'voxbreast probe' can run this scene", "probe.indenter",
          "run voxbreast probe, or give the indenter a start");
  using Clock = std::chrono::steady_clock;
  PhaseTimings timings;
  const Clock::time_point start = options.command_start.value_or(Clock::now());
  Clock::time_point phase_start = start;  // setup counts from the command's start (scene, device)
  // Ends the phase under way (adding its time to `slot`) and starts `next`.
  const auto next_phase = [&](double& slot, const char* next) {
    const Clock::time_point now = Clock::now();
    slot += std::chrono::duration<double>(now - phase_start).count();
    phase_start = now;
    if (next && options.on_phase) options.on_phase(next);
  };
  if (options.on_phase) options.on_phase("setup");
  std::unique_lock io(file_io_mutex());
  const PreparedModel model = prepare_model(scene, &cl.info);
  if (options.full_outputs && model.ct && scene.output.warped_ct_dicom)  // refuse before the run, not after it
    check_dicom_series_replaceable((options.final_dir.empty() ? out_dir : options.final_dir) + "/warped_ct_dicom");
  io.unlock();
  check_positioning(scene, model.lattice);  // a misnamed tumour tissue fails now, not after the run
  next_phase(timings.setup_s, "kernel build");
  Simulator sim(scene, model.lattice, model.elements, cl);
  std::optional<ReferenceState> reference;
  if (scene.reference_state.active) {  // the run starts from the CT resting on the unloaded state
    next_phase(timings.kernel_build_s, "reference state");
    reference = estimate_reference_state(scene, model.lattice, cl, options.on_reference_iteration, options.on_progress);
    sim.set_rest_offsets(reference->rest_offset_m);
    next_phase(timings.reference_state_s, "solve");
  } else {
    next_phase(timings.kernel_build_s, "solve");
  }
  if (options.on_start) options.on_start(model, sim);
  RunOutput result = run_simulation(scene, model.lattice, model.elements, sim, options.on_progress);
  if (reference) result.state.rest_offset_m = reference->rest_offset_m;
  std::optional<ReproducibilityResult> repro;
  if (scene.reproducibility.active) {
    next_phase(timings.solve_s, "reproducibility");
    repro = run_reproducibility(scene, model.lattice, cl, reference ? &reference->rest_offset_m : nullptr,
                                options.on_perturbed_run, options.on_progress);
    next_phase(timings.reproducibility_s, "outputs");
  } else {
    next_phase(timings.solve_s, "outputs");
  }

  SimulationReport report;
  report.summary = result.summary;
  report.warnings = model.warnings;
  if (!result.summary.unconverged_reason.empty()) report.unconverged.push_back(result.summary.unconverged_reason);
  if (auto hint = float_floor_hint(scene, result.summary)) report.warnings.push_back(*hint);
  if (reference && !reference->converged) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "the unloaded reference state is %.3g mm from the CT after %zu iterations (tolerance %.3g mm)",
                  1e3 * reference->residual_max_m, reference->history.size(), 1e3 * scene.reference_state.tolerance_m);
    report.unconverged.push_back(text);
  }
  io.lock();
  nlohmann::json summary = summary_to_json(result.summary, scene);
  summary["model"] = model_mass_to_json(model.lattice, tissue_masses(scene, model.lattice, model.elements));
  report.positioning = compute_positioning_metrics(scene, model.lattice, model.elements, result.summary, result.state);
  if (reference) {
    report.positioning.reference_state = ReferenceStateMetrics{int(reference->history.size()), reference->converged,
                                                               reference->residual_max_m, reference->residual_rms_m,
                                                               reference->max_rest_offset_m};
    summary["reference_state"] = reference_state_to_json(*reference, scene.reference_state);
  }
  report.positioning.reproducibility = repro;
  if (repro)
    if (auto unsettled = unsettled_runs_warning(*repro)) report.unconverged.push_back(*unsettled);
  report.warnings.insert(report.warnings.end(), report.unconverged.begin(), report.unconverged.end());
  summary["positioning"] = positioning_to_json(report.positioning);
  if (repro) summary["positioning"]["reproducibility"] = reproducibility_to_json(*repro, scene.reproducibility);
  if (options.full_outputs) {
    if (repro) write_reproducibility_csv(out_dir + "/reproducibility.csv", *repro);
    write_result_h5(out_dir + "/result.h5", model.lattice, scene, result.state, result.frames, result.summary);
    if (model.ct) {
      const Clock::time_point image_start = Clock::now();
      summary["image_outputs"] =
          write_image_outputs(out_dir, scene, model, result.state, options.on_image_progress);
      timings.image_outputs_s = std::chrono::duration<double>(Clock::now() - image_start).count();
      const OutputSpec& out = scene.output;
      report.image_outputs = out.dvf || out.warped_ct || out.warped_ct_dicom || out.fields;
    }
    if (scene.output.surfaces) {
      summary["mesh_outputs"] = write_mesh_outputs(out_dir, model.lattice, result.state, result.frames);
      for (const auto& file : write_device_meshes(out_dir, scene, result.summary.simulated_time_s, result.frames))
        summary["mesh_outputs"]["files"].push_back(file);
      report.mesh_outputs = true;
    }
  }
  if (model.ct || !report.warnings.empty()) summary["warnings"] = report.warnings;
  next_phase(timings.outputs_s, nullptr);
  // wall_time_s is the whole command; the run's own time is timings.solve_s (steps_per_second's).
  timings.total_s = std::chrono::duration<double>(Clock::now() - start).count();
  report.summary.wall_time_s = result.summary.wall_time_s = timings.total_s;
  summary["wall_time_s"] = timings.total_s;
  summary["timings"] = {{"setup_s", timings.setup_s},
                        {"kernel_build_s", timings.kernel_build_s},
                        {"reference_state_s", timings.reference_state_s},
                        {"solve_s", timings.solve_s},
                        {"reproducibility_s", timings.reproducibility_s},
                        {"outputs_s", timings.outputs_s},
                        {"image_outputs_s", timings.image_outputs_s},
                        {"total_s", timings.total_s}};
  report.timings = timings;
  write_metrics_csv(out_dir + "/metrics.csv", result.summary, report.positioning);
  write_text_atomically(out_dir + "/summary.json", summary.dump(2) + "\n");
  return report;
}

}  // namespace vb::app
