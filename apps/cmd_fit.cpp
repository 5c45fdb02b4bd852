// voxbreast fit SCENE.toml --out DIR — estimates tissue elasticity from an observed posture
// change (inverse fitting, docs/FIT.md); resumes from DIR/checkpoint.json after a kill.
//   voxbreast fit data-samples/fit/scene_fit.toml --out out/fit
#include <cstdio>
#include <memory>

#include "apps/commands.hpp"
#include "apps/fit_batch.hpp"
#include "apps/fit_pipeline.hpp"
#include "apps/simulation_setup.hpp"
#include "engine/error.hpp"

namespace vb::app {
namespace {

struct FitCommandOptions {
  std::string scene, out, device, precision, truth, make_observation, make_labels, make_surface, cases, devices;
  int labels_subdivide = 3;
  int surface_label = 0;
  bool retry_failed = false;
  double noise_mm = 0;
  std::uint64_t seed = 1;
  int stop_after = 0;
  bool quiet = false, no_plots = false;
};

int run_fit_command(const FitCommandOptions& o) {
  if (!o.cases.empty()) {
    require(o.scene.empty() && !o.out.empty(), "--cases runs the scenes of a list: give no scene file, and --out",
            "voxbreast fit --cases", "voxbreast fit --cases cases.csv --out DIR");
    FitBatchOptions b;
    b.cases_csv = o.cases;
    b.out = o.out;
    b.devices = o.devices.empty() ? o.device : o.devices;
    b.stop_after = std::size_t(o.stop_after);
    b.retry_failed = o.retry_failed;
    b.quiet = o.quiet;
    b.plots = !o.no_plots;
    return run_fit_batch(b);
  }
  require(!o.scene.empty(), "a scene file (or --cases) is needed", "voxbreast fit", "voxbreast fit SCENE.toml --out DIR");
  const Scene scene = load_scene(o.scene, o.precision);
  require(!o.out.empty() || !o.make_observation.empty() || !o.make_labels.empty() || !o.make_surface.empty(),
          "--out is required", "voxbreast fit",
          "give --out DIR");
  const ClContext cl(select_device(o.device));
  if (!o.make_surface.empty()) {
    const double largest = write_synthetic_surface(scene, cl, o.make_surface, o.surface_label);
    std::printf("wrote %s: the boundary of label %d after the posture change with the scene's materials (largest %.3f mm)\n",
                o.make_surface.c_str(), o.surface_label, largest * 1e3);
    if (o.make_observation.empty() && o.make_labels.empty()) return 0;
  }
  if (!o.make_labels.empty()) {
    const double largest = write_synthetic_labels(scene, cl, o.make_labels, o.labels_subdivide);
    std::printf("wrote %s: the model's labels after the posture change with the scene's materials (largest %.3f mm)\n",
                o.make_labels.c_str(), largest * 1e3);
    if (o.make_observation.empty()) return 0;
  }
  if (!o.make_observation.empty()) {
    const double largest = write_synthetic_observation(scene, cl, o.make_observation, o.noise_mm * 1e-3, o.seed);
    std::printf("wrote %s: the posture change with the scene's materials (largest %.3f mm), noise %.3g mm\n",
                o.make_observation.c_str(), largest * 1e3, o.noise_mm);
    return 0;
  }
  FitRunOptions options;
  options.truth_path = o.truth;
  options.stop_after_iterations = o.stop_after;
  options.plots = !o.no_plots;
  if (!o.quiet)
    options.on_iteration = [](const FitIteration& r) {
      std::printf("iteration %3d  cost %.6g  rms %.4f mm  within 1 mm %.2f%%  forward solves %lld  %.1f s\n",
                  r.iteration, r.cost, r.rms_mm, 100 * r.within_1mm, (long long)r.forward_solves, r.wall_time_s);
      std::fflush(stdout);
    };
  const nlohmann::json summary = fit_scene(scene, cl, o.out, options);
  if (!summary.value("finished", false)) {
    std::printf("fit stopped after --stop-after iterations; run the same command again to continue\n");
    return 3;
  }
  const auto& f = summary.at("final");
  std::printf("fit: %s, %d iterations, %lld forward solves, %.1f s: rms %.4f mm, %.2f%% within 1 mm (%s); wrote %s\n",
              summary.at("method").get<std::string>().c_str(), summary.at("iterations").get<int>(),
              (long long)summary.at("forward_solves").get<std::int64_t>(), summary.at("wall_time_s").get<double>(),
              f.at("rms_mm").get<double>(), 100 * f.at("within_1mm").get<double>(),
              summary.at("stop_reason").get<std::string>().c_str(), o.out.c_str());
  return 0;
}

}  // namespace

Command add_fit(CLI::App& app) {
  auto o = std::make_shared<FitCommandOptions>();
  auto* sub = app.add_subcommand("fit", "Estimate tissue elasticity from an observed posture change ([fit], docs/FIT.md)");
  sub->add_option("scene", o->scene, "scene file (TOML) with a [fit] table")->check(CLI::ExistingFile);
  sub->add_option("--cases", o->cases, "batch: a CSV with a 'scene' column (and optional 'truth'), one fit per row")
      ->check(CLI::ExistingFile);
  sub->add_option("--devices", o->devices, "batch: OpenCL devices, one worker each (as `sweep --devices`)");
  sub->add_flag("--retry-failed", o->retry_failed, "batch: run failed cases again");
  sub->add_option("--out,-o", o->out, "output folder (restarting into it resumes the fit)");
  sub->add_option("--truth", o->truth, "true displacement field (NIfTI): summary.json compares the fit with it")
      ->check(CLI::ExistingFile);
  sub->add_option("--make-observation", o->make_observation,
                  "instead of fitting: write the posture change with the scene's materials as a NIfTI DVF (validation)");
  sub->add_option("--make-observed-labels", o->make_labels,
                  "instead of fitting: write the model's labels after the posture change with the scene's materials "
                  "(NIfTI label map, for fit.observed_labels; validation)");
  sub->add_option("--make-observed-surface", o->make_surface,
                  "instead of fitting: write the boundary of a region after the posture change with the scene's "
                  "materials (binary STL, mm, LPS; for fit.observed_surface; validation)");
  sub->add_option("--surface-label", o->surface_label,
                  "with --make-observed-surface: the region, 0 the body outline (default) or a label value")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--labels-subdivide", o->labels_subdivide,
                  "with --make-observed-labels: label voxels per lattice spacing along each axis (default 3)")
      ->check(CLI::Range(1, 8));
  sub->add_option("--noise-mm", o->noise_mm, "with --make-observation: Gaussian noise per component (mm)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--seed", o->seed, "with --make-observation: seed of the noise (default 1)");
  sub->add_option("--device,-d", o->device, "OpenCL device: gpu, cpu, an index or a name (default $VOXBREAST_DEVICE, else first GPU)");
  sub->add_option("--precision", o->precision, "override solver.precision")->check(CLI::IsMember({"float", "double"}));
  sub->add_option("--stop-after", o->stop_after, "stop after N more iterations (batch: N cases per process); resumable");
  sub->add_flag("--no-plots", o->no_plots, "do not draw history.png");
  sub->add_flag("--quiet,-q", o->quiet, "no per-iteration lines");
  return {sub, [o] { return run_fit_command(*o); }};
}

}  // namespace vb::app
