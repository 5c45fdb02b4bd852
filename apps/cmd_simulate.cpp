// voxbreast simulate SCENE.toml --out DIR — runs a scene and writes summary.json, metrics.csv and result.h5.
//   voxbreast simulate data-samples/breast_phantom.toml --out out/phantom
#include <cstdio>
#include <memory>

#include "apps/commands.hpp"
#include "apps/device_mesh_outputs.hpp"
#include "apps/image_outputs.hpp"
#include "apps/mesh_outputs.hpp"
#include "apps/progress.hpp"
#include "apps/simulation_setup.hpp"
#include "engine/sim/run.hpp"
#include "engine/study/positioning_metrics.hpp"
#include "io/atomic_file.hpp"
#include "io/hdf5_result.hpp"
#include "io/json_summary.hpp"
#include "io/metrics_csv.hpp"

namespace vb::app {
namespace {

struct SimulateOptions {
  std::string scene, out, device, precision, series;
  bool quiet = false, allow_gaps = false;
};

int run_simulate(const SimulateOptions& o) {
  Scene scene = load_scene(o.scene, o.precision);
  if (!o.series.empty()) scene.model.series_uid = o.series;
  scene.model.allow_gaps = scene.model.allow_gaps || o.allow_gaps;
  ensure_output_dir(o.out);  // fail before computing, not after
  const PreparedModel model = prepare_model(scene);
  check_positioning(scene, model.lattice);  // a misnamed tumour tissue fails now, not after the run
  const ClContext cl(select_device(o.device));
  Simulator sim(scene, model.lattice, model.elements, cl);
  if (!o.quiet)
    std::fprintf(stderr, "voxbreast: %zu elements, %zu connections, dt = %.3g s (%s), device %s, %s\n",
                 model.lattice.element_count(), model.lattice.connection_count, sim.dt_s(),
                 sim.time_step().automatic ? "auto" : "given", cl.info.name.c_str(),
                 scene.solver.precision == Precision::Double ? "double" : "float");
  Progress bar(!o.quiet);
  const RunOutput result = run_simulation(scene, model.lattice, model.elements, sim, [&](const RunProgress& p) {
    char text[160];
    std::snprintf(text, sizeof text, "step %lld  t=%.4g s  residual %.2e  speed %.2e", (long long)p.step, p.time_s,
                  p.residual, p.speed_ratio);
    bar.update(double(p.step) / double(p.max_steps), text);
  });
  bar.finish();

  const std::string h5 = o.out + "/result.h5", json = o.out + "/summary.json", csv = o.out + "/metrics.csv";
  write_result_h5(h5, model.lattice, scene, result.state, result.frames, result.summary);
  nlohmann::json summary = summary_to_json(result.summary, scene);
  const PositioningMetrics metrics =
      compute_positioning_metrics(scene, model.lattice, model.elements, result.summary, result.state);
  summary["positioning"] = positioning_to_json(metrics);
  write_metrics_csv(csv, result.summary, metrics);
  if (model.ct) {
    summary["image_outputs"] = write_image_outputs(o.out, scene, model.lattice, *model.ct, result.state);
    summary["warnings"] = model.warnings;
  }
  if (scene.output.surfaces) {
    summary["mesh_outputs"] = write_mesh_outputs(o.out, model.lattice, result.state, result.frames);
    for (const auto& file : write_device_meshes(o.out, scene, result.summary.simulated_time_s, result.frames))
      summary["mesh_outputs"]["files"].push_back(file);
  }
  write_text_atomically(json, summary.dump(2) + "\n");
  const RunSummary& s = result.summary;
  std::printf("%s after %lld steps (%.4g s simulated, %.1f s wall, %.0f steps/s); max displacement %.3f mm\n",
              s.converged ? "equilibrium reached" : ("stopped at " + s.stop_reason).c_str(), (long long)s.steps,
              s.simulated_time_s, s.wall_time_s, s.steps_per_second, 1e3 * s.max_displacement_m);
  for (const std::string& w : model.warnings) std::fprintf(stderr, "voxbreast: warning: %s\n", w.c_str());
  for (const TorusResult& t : s.tori)
    std::printf("torus %s: force %.4g N, %lld contact elements, peak pressure %.4g Pa\n", t.name.c_str(),
                t.force_n.norm(), (long long)t.contact_elements, t.peak_pressure_pa);
  if (metrics.tumour)
    std::printf("tumour '%s' centroid moved %.3f mm\n", metrics.tumour->tissue.c_str(),
                1e3 * metrics.tumour->displacement_m().norm());
  std::printf("wrote %s\nwrote %s\nwrote %s\n", json.c_str(), csv.c_str(), h5.c_str());
  const OutputSpec& out = scene.output;
  if (model.ct && (out.dvf || out.warped_ct || out.warped_ct_dicom || out.fields))
    std::printf("wrote DVF, warped CT and fields on the CT grid in %s/\n", o.out.c_str());
  if (scene.output.surfaces)
    std::printf("wrote surface meshes (.vtp, .stl, .ply)%s and lattice.vtu in %s/\n",
                scene.tori.empty() ? "" : ", device meshes", o.out.c_str());
  return 0;
}

}  // namespace

Command add_simulate(CLI::App& app) {
  auto o = std::make_shared<SimulateOptions>();
  auto* sub = app.add_subcommand("simulate", "Run a scene; write summary.json and result.h5");
  sub->add_option("scene", o->scene, "scene file (TOML)")->required()->check(CLI::ExistingFile);
  sub->add_option("--out,-o", o->out, "output folder")->required();
  sub->add_option("--device,-d", o->device, "OpenCL device: gpu, cpu, an index or a name (default $VOXBREAST_DEVICE, else first GPU)");
  sub->add_option("--precision", o->precision, "override solver.precision")->check(CLI::IsMember({"float", "double"}));
  sub->add_option("--series", o->series, "DICOM SeriesInstanceUID when the CT folder holds several series");
  sub->add_flag("--allow-gaps", o->allow_gaps, "accept unevenly spaced DICOM slices (with a warning)");
  sub->add_flag("--quiet,-q", o->quiet, "no progress display");
  return {sub, [o] { return run_simulate(*o); }};
}

}  // namespace vb::app
