#include "apps/simulation_pipeline.hpp"

#include <mutex>

#include "apps/device_mesh_outputs.hpp"
#include "engine/error.hpp"
#include "apps/image_outputs.hpp"
#include "apps/mesh_outputs.hpp"
#include "io/atomic_file.hpp"
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

}  // namespace

SimulationReport simulate_scene(const Scene& scene, const ClContext& cl, const std::string& out_dir,
                                const SimulationOptions& options) {
  // The [probe] indenter may have no start: only voxbreast probe places it.
  require(!scene.probe.active || scene.indenters[scene.probe.indenter].has_start,
          "the [probe] indenter has no start, so only 'voxbreast probe' can run this scene", "probe.indenter",
          "run voxbreast probe, or give the indenter a start");
  std::unique_lock io(file_io_mutex());
  const PreparedModel model = prepare_model(scene);
  io.unlock();
  check_positioning(scene, model.lattice);  // a misnamed tumour tissue fails now, not after the run
  Simulator sim(scene, model.lattice, model.elements, cl);
  if (options.on_start) options.on_start(model, sim);
  const RunOutput result = run_simulation(scene, model.lattice, model.elements, sim, options.on_progress);

  SimulationReport report;
  report.summary = result.summary;
  report.warnings = model.warnings;
  io.lock();
  nlohmann::json summary = summary_to_json(result.summary, scene);
  report.positioning = compute_positioning_metrics(scene, model.lattice, model.elements, result.summary, result.state);
  summary["positioning"] = positioning_to_json(report.positioning);
  write_metrics_csv(out_dir + "/metrics.csv", result.summary, report.positioning);
  if (options.full_outputs) {
    write_result_h5(out_dir + "/result.h5", model.lattice, scene, result.state, result.frames, result.summary);
    if (model.ct) {
      summary["image_outputs"] = write_image_outputs(out_dir, scene, model.lattice, *model.ct, result.state);
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
  if (model.ct) summary["warnings"] = model.warnings;
  write_text_atomically(out_dir + "/summary.json", summary.dump(2) + "\n");
  return report;
}

}  // namespace vb::app
