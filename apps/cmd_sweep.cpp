// voxbreast sweep SCENE.toml --vary KEY=VALUES ... --out DIR — runs the scene once per point of a
// grid of scene values; resumable; spread over devices (--devices) and MPI ranks (mpirun).
//   voxbreast sweep data-samples/phantom/scene.toml --vary +materials.adipose.E=2000:6000:3
//       --vary gravity.posture=prone,supine --out out/sweep
//   mpirun -n 2 voxbreast sweep ...      (one device per rank)
// Layout, keys and columns: docs/SWEEP.md.
#include <cstdio>
#include <memory>
#include <mutex>

#include "apps/commands.hpp"
#include "apps/progress.hpp"
#include "apps/simulation_pipeline.hpp"
#include "apps/sweep_plots.hpp"
#include "engine/error.hpp"
#include "engine/study/sweep.hpp"
#include "engine/study/sweep_devices.hpp"
#include "io/scene_file.hpp"

namespace vb::app {
namespace {

struct SweepCommandOptions {
  std::string scene, out, devices, outputs = "minimal";
  std::vector<std::string> vary;
  std::size_t stop_after = 0;
  bool retry_failed = false, quiet = false, no_plots = false, dry_run = false;
};

std::string case_values(const SweepPlan& plan, std::size_t index) {
  std::string text;
  const std::vector<std::string> values = plan.grid.values_of(index);
  for (std::size_t p = 0; p < values.size(); ++p)
    text += (p ? "  " : "") + plan.grid.parameters()[p].key + "=" + toml_value_plain(values[p]);
  return text;
}

/// One OpenCL context per worker: every device of --devices, or under MPI the rank's one device.
/// Runs one case of the sweep into its working folder (the same pipeline as `simulate`).
void run_case(const SweepCase& c, const ClContext& cl, bool full_outputs) {
  const std::string scene_path = c.final_dir + "/scene.toml";
  Scene scene = parse_scene_text(c.scene_text, scene_path);
  scene.source_path = scene_path;
  SimulationOptions options;
  options.full_outputs = full_outputs;
  try {
    simulate_scene(scene, cl, c.work_dir, options);
  } catch (const cl::Error& e) {
    throw Error("OpenCL call " + std::string(e.what()) + " failed: " + cl_status_name(e.err()), "case " + c.id);
  }
}

int run_sweep_command(const SweepCommandOptions& o) {
  std::vector<SweepParameter> parameters;
  for (const std::string& v : o.vary) parameters.push_back(parse_vary(v));
  MpiWorld world;
  const std::string rank_tag = world.size() > 1 ? "[rank " + std::to_string(world.rank()) + "] " : "";
  const SweepPlan plan = plan_sweep(o.scene, std::move(parameters));
  if (o.dry_run) {
    if (world.rank() == 0) {
      std::printf("%zu case%s; every case scene passed the scene checks\n", plan.grid.size(),
                  plan.grid.size() == 1 ? "" : "s");
      for (std::size_t i = 0; i < plan.grid.size(); ++i) std::printf("%5zu  %s\n", i + 1, case_values(plan, i).c_str());
    }
    return 0;
  }

  const std::vector<std::unique_ptr<ClContext>> contexts = open_worker_contexts(o.devices, world);

  SweepOptions options;
  options.out_dir = o.out;
  options.outputs = o.outputs;
  options.stop_after = o.stop_after;
  options.retry_failed = o.retry_failed;
  options.workers = worker_names(contexts);
  if (!o.quiet && world.rank() == 0)
    std::printf("sweep: %zu cases, %d rank%s × %zu device%s (%s), outputs %s, into %s\n", plan.grid.size(),
                world.size(), world.size() == 1 ? "" : "s", contexts.size(), contexts.size() == 1 ? "" : "s",
                contexts.front()->info.name.c_str(), o.outputs.c_str(), o.out.c_str());
  Progress bar(!o.quiet && world.rank() == 0);
  std::vector<std::string> running(contexts.size());
  options.on_progress = [&](const SweepProgress& p) {
    running[p.worker] = p.kind == SweepProgress::Kind::Started ? p.id : "";
    if (p.kind == SweepProgress::Kind::Finished && !o.quiet) {
      char line[160];
      std::snprintf(line, sizeof line, "%scase %s  %-6s %6.1f s  ", rank_tag.c_str(), p.id.c_str(), p.status.c_str(),
                    p.wall_time_s);
      bar.print_above(line + case_values(plan, p.index) + (p.error.empty() ? "" : "\n    " + p.error) + "\n");
    }
    std::string now;
    for (const std::string& id : running) now += id.empty() ? "" : " " + id;
    bar.update(double(p.done) / double(std::max<std::size_t>(p.total, 1)),
               std::to_string(p.done) + "/" + std::to_string(p.total) + " cases" + (now.empty() ? "" : ", running" + now));
  };
  const bool full = o.outputs == "full";
  const SweepOutcome outcome = run_sweep(plan, options, world, [&](const SweepCase& c, std::size_t worker) {
    run_case(c, *contexts[worker], full);
  });
  bar.finish();
  world.finalize();  // before starting Python for the plots
  if (world.rank() != 0) return 0;

  const SweepTablesReport& t = outcome.tables;
  for (const std::string& w : outcome.warnings) std::fprintf(stderr, "voxbreast: warning: %s\n", w.c_str());
  if (!o.quiet && outcome.run.skipped)
    std::printf("%zu cases were finished before this run and were kept\n", outcome.run.skipped);
  std::printf("sweep: %zu cases: %zu ok, %zu failed, %zu not run; wrote %s/metrics.csv and timing.csv\n",
              plan.grid.size(), t.ok, t.failed, t.pending, o.out.c_str());
  if (t.pending) {
    std::printf("run the same command again to finish the sweep\n");
    return 3;
  }
  if (!o.no_plots) {
    std::fflush(stdout);
    if (const std::string message = draw_sweep_plots(o.out); !message.empty()) std::printf("%s\n", message.c_str());
  }
  return 0;
}

}  // namespace

Command add_sweep(CLI::App& app) {
  auto o = std::make_shared<SweepCommandOptions>();
  auto* sub = app.add_subcommand("sweep", "Run a scene over a grid of scene values; resumable; devices and MPI ranks");
  sub->add_option("scene", o->scene, "scene file (TOML)")->required()->check(CLI::ExistingFile);
  sub->add_option("--vary,-v", o->vary,
                  "KEY=FROM:TO:N[:log] or KEY=a,b,c; +KEY adds a key the scene lacks; repeat for a grid (docs/SWEEP.md)")
      ->take_all()
      ->allow_extra_args(false);
  sub->add_option("--out,-o", o->out, "sweep folder (restarting into it continues the sweep)")->required();
  sub->add_option("--devices", o->devices,
                  "OpenCL devices, one worker each: all, or a list of --device selectors (0,1; cpu,cpu). "
                  "Default: one device, $VOXBREAST_DEVICE or the first GPU. Under mpirun: one per rank, spread over all");
  sub->add_option("--outputs", o->outputs, "minimal (summary.json per case) or full (everything simulate writes)")
      ->check(CLI::IsMember({"minimal", "full"}));
  sub->add_option("--stop-after", o->stop_after, "run at most N cases (per process), then stop; rerun to continue");
  sub->add_flag("--retry-failed", o->retry_failed, "run failed cases again");
  sub->add_flag("--dry-run", o->dry_run, "list the cases and check their scenes; run nothing");
  sub->add_flag("--no-plots", o->no_plots, "do not draw the PNG plots at the end");
  sub->add_flag("--quiet,-q", o->quiet, "no progress display or per-case lines");
  return {sub, [o] { return run_sweep_command(*o); }};
}

}  // namespace vb::app
