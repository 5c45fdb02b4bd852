// voxbreast simulate SCENE.toml --out DIR — runs a scene and writes summary.json, metrics.csv and result.h5.
//   voxbreast simulate data-samples/breast_phantom.toml --out out/phantom
#include <chrono>
#include <cstdio>
#include <memory>

#include "apps/commands.hpp"
#include "apps/progress.hpp"
#include "apps/simulation_pipeline.hpp"
#include "io/atomic_file.hpp"
#include "io/scene_file.hpp"
#include "io/scene_overrides.hpp"
#include "io/run_folder.hpp"

namespace vb::app {
namespace {

struct SimulateOptions {
  std::string scene, out, device, precision, series;
  std::vector<std::string> settings;  ///< --set KEY=VALUE
  bool quiet = false, allow_gaps = false;
  double status_interval_s = 10;
};

int run_simulate(const SimulateOptions& o) {
  const auto command_start = std::chrono::steady_clock::now();
  std::vector<SceneOverride> overrides;  // --set values, applied to the scene's text
  for (const std::string& s : o.settings) overrides.push_back(parse_scene_setting(s));
  Scene scene = overrides.empty() ? load_scene(o.scene, o.precision) : parse_scene_file(o.scene, overrides);
  if (!overrides.empty() && !o.precision.empty())
    scene.solver.precision = o.precision == "double" ? Precision::Double : Precision::Float;
  if (!o.series.empty()) scene.model.series_uid = o.series;
  scene.model.allow_gaps = scene.model.allow_gaps || o.allow_gaps;
  // Fails before computing, not after; the run writes into its staging folder until commit().
  RunFolder folder(o.out, "simulate", {"summary.json", "metrics.csv", "result.h5"});
  const ClContext cl(select_device(o.device));
  Progress bar(!o.quiet, o.status_interval_s);
  SimulationOptions options;
  options.command_start = command_start;
  show_progress(bar, scene, options);
  options.on_reference_iteration = [&](const ReferenceIteration& r) {
    if (o.quiet) return;
    bar.phase("reference state");
    std::fprintf(stderr, "voxbreast: unloaded state, iteration %d (step %.3g): lands %.4f mm from the CT (rms %.4f mm, %lld steps)\n",
                 r.iteration, r.step, 1e3 * r.residual_max_m, 1e3 * r.residual_rms_m, (long long)r.steps);
  };
  options.on_perturbed_run = [&](const PerturbedRun& r) {
    if (o.quiet) return;
    bar.phase("reproducibility");
    std::fprintf(stderr, "voxbreast: posture %d/%d %s device (roll %.2f, pitch %.2f, yaw %.2f deg): tumour at (%.2f, %.2f, %.2f) mm%s\n",
                 r.index, scene.reproducibility.perturbations, r.device ? "with" : "without", r.rpy_deg.x(),
                 r.rpy_deg.y(), r.rpy_deg.z(), 1e3 * r.tumour_centroid_m.x(), 1e3 * r.tumour_centroid_m.y(),
                 1e3 * r.tumour_centroid_m.z(), r.converged ? "" : ", stopped before equilibrium");
  };
  options.final_dir = o.out;
  const SimulationReport report = simulate_scene(scene, cl, folder.staging(), options);
  folder.commit();
  bar.finish();

  const RunSummary& s = report.summary;
  std::printf("%s after %lld steps (%.4g s simulated, %.1f s wall, %.0f steps/s); max displacement %.3f mm\n",
              s.converged                       ? "equilibrium reached"
              : s.stop_reason == "equilibrium" ? "equilibrium met only trivially"
                                                : ("stopped at " + s.stop_reason).c_str(),
              (long long)s.steps,
              s.simulated_time_s, s.wall_time_s, s.steps_per_second, 1e3 * s.max_displacement_m);
  for (const std::string& w : report.warnings) std::fprintf(stderr, "voxbreast: warning: %s\n", w.c_str());
  for (const TorusResult& t : s.tori)
    std::printf("torus %s: force %.4g N, %lld contact elements, peak pressure %.4g Pa\n", t.name.c_str(),
                t.force_n.norm(), (long long)t.contact_elements, t.peak_pressure_pa);
  if (const auto& tumour = report.positioning.tumour) {
    // With a reference state the displacement is measured from the CT, so it is the change from
    // the CT's posture to the scene's, both loaded by gravity.
    const std::string from = scene.reference_state.active && !scene.reference_state.ct_posture.empty()
                                 ? " from the CT (" + scene.reference_state.ct_posture + ")"
                                 : " from the CT";
    const std::string to = scene.gravity.posture.empty() ? "" : " to " + scene.gravity.posture;
    std::printf("tumour '%s' centroid moved %.3f mm%s%s%s\n", tumour->tissue.c_str(),
                1e3 * tumour->displacement_m().norm(), from.c_str(), to.c_str(),
                scene.reference_state.active ? ", simulated from the unloaded state"
                                             : " (the CT taken as unloaded: add [reference_state])");
  }
  if (const auto& r = report.positioning.reference_state)
    std::printf("unloaded reference state: %d iterations, lands %.4f mm from the CT; it lies up to %.3f mm from the CT\n",
                r->iterations, 1e3 * r->residual_max_m, 1e3 * r->max_rest_offset_m);
  if (const auto& r = report.positioning.reproducibility) {
    if (r->with_device)
      std::printf("tumour spread over %d postures with the device: std %.3f mm, max %.3f mm\n", r->with_device->runs,
                  1e3 * r->with_device->std_m, 1e3 * r->with_device->max_m);
    std::printf("tumour spread over %d postures without a device: std %.3f mm, max %.3f mm\n", r->without_device.runs,
                1e3 * r->without_device.std_m, 1e3 * r->without_device.max_m);
  }
  std::printf("wrote %s/summary.json\nwrote %s/metrics.csv\nwrote %s/result.h5\n", o.out.c_str(), o.out.c_str(),
              o.out.c_str());
  if (report.image_outputs) std::printf("wrote DVF, warped CT and fields on the CT grid in %s/\n", o.out.c_str());
  if (report.mesh_outputs)
    std::printf("wrote surface meshes (.vtp, .stl, .ply)%s and lattice.vtu in %s/\n",
                scene.tori.empty() ? "" : ", device meshes", o.out.c_str());
  if (report.unconverged.empty()) return 0;
  std::fprintf(stderr, "voxbreast: the result is not converged (see the warnings above and summary.json); exit status %d\n",
               kExitNotConverged);
  return kExitNotConverged;
}

}  // namespace

Command add_simulate(CLI::App& app) {
  auto o = std::make_shared<SimulateOptions>();
  auto* sub = app.add_subcommand("simulate", "Run a scene; write summary.json and result.h5");
  sub->add_option("scene", o->scene, "scene file (TOML)")->required()->check(CLI::ExistingFile);
  sub->add_option("--out,-o", o->out, "output folder")->required();
  sub->add_option("--device,-d", o->device, "OpenCL device: gpu, cpu, an index or a name (default $VOXBREAST_DEVICE, else first GPU)");
  sub->add_option("--set", o->settings, "KEY=VALUE: set one scene value by dotted key (materials.adipose.E=3000); "
                                        "+KEY adds a key the scene lacks; repeatable (docs/SCENE.md)")
      ->allow_extra_args(false);
  sub->add_option("--precision", o->precision, "override solver.precision")->check(CLI::IsMember({"float", "double"}));
  sub->add_option("--series", o->series, "DICOM SeriesInstanceUID when the CT folder holds several series");
  sub->add_flag("--allow-gaps", o->allow_gaps, "accept unevenly spaced DICOM slices (with a warning)");
  sub->add_flag("--quiet,-q", o->quiet, "no progress display");
  sub->add_option("--status-interval", o->status_interval_s,
                  "seconds between status lines on stderr when it is not a terminal (default 10)")
      ->check(CLI::PositiveNumber);
  return {sub, [o] { return run_simulate(*o); }};
}

}  // namespace vb::app
