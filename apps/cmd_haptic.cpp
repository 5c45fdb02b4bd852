// voxbreast haptic SCENE.toml --trajectory traj.csv --out DIR — plays a scripted probe trajectory
// against the scene in real time: the deformation updates on the OpenCL device while the probe's
// force is output at --rate-hz (docs/HAPTICS.md). Writes haptic.csv and haptic_summary.json.
//   voxbreast haptic data-samples/haptic/block.toml --trajectory data-samples/haptic/press.csv --out out/haptic
#include <cstdio>
#include <memory>

#include "apps/commands.hpp"
#include "apps/simulation_setup.hpp"
#include "engine/haptic/haptic_report.hpp"
#include "io/atomic_file.hpp"
#include "io/numeric_csv.hpp"

namespace vb::app {
namespace {

struct HapticCliOptions {
  std::string scene, trajectory, out, device, precision;
  double rate_hz = 1000, seconds = 0;
  int probe = 1, steps_per_update = 0;
  bool quiet = false, no_realtime = false;
};

int run_haptic(const HapticCliOptions& o) {
  const Scene scene = load_scene(o.scene, o.precision);
  const ProbeTrajectory trajectory = trajectory_from_rows(
      read_numeric_csv(o.trajectory, {"time_s", "x_mm", "y_mm", "z_mm"}), o.trajectory);
  const OutputDir output_dir(o.out);
  const ClContext cl(select_device(o.device));
  const PreparedModel model = prepare_model(scene, &cl.info);
  HapticOptions options;
  options.probe = std::size_t(o.probe - 1);
  options.steps_per_update = o.steps_per_update;
  HapticProbe probe(scene, model.lattice, model.elements, cl, options);
  HapticLoopOptions loop;
  loop.rate_hz = o.rate_hz;
  loop.seconds = o.seconds;
  loop.realtime = !o.no_realtime;
  if (!o.quiet)
    std::fprintf(stderr, "voxbreast: %zu elements, dt = %.3g s, device %s; force output at %g Hz for %g s\n",
                 model.lattice.element_count(), probe.simulator().dt_s(), cl.info.name.c_str(), o.rate_hz,
                 loop.seconds > 0 ? loop.seconds : trajectory.end_s());
  const HapticLoopResult r = run_haptic_loop(probe, trajectory, loop);
  write_text_atomically(o.out + "/haptic.csv", haptic_log_csv(r));
  write_text_atomically(o.out + "/haptic_summary.json",
                        haptic_summary_json(r, loop, probe, model.lattice.element_count()).dump(2) + "\n");
  std::printf("force output %.1f Hz (target %g Hz): interval mean %.3f ms, p99 %.3f ms, max %.3f ms; "
              "%lld deformation updates (%.1f Hz, %.0f steps/s)\n",
              r.achieved_rate_hz, o.rate_hz, 1e3 * r.intervals.mean_s, 1e3 * r.intervals.p99_s,
              1e3 * r.intervals.max_s, (long long)r.updates, r.update_rate_hz,
              r.wall_s > 0 ? double(r.steps) / r.wall_s : 0.0);
  std::printf("wrote %s/haptic.csv\nwrote %s/haptic_summary.json\n", o.out.c_str(), o.out.c_str());
  // A validity warning, not a failure: the run went on and the summary says folded.
  if (const std::string fold = haptic_fold_warning(r); !fold.empty())
    std::fprintf(stderr, "voxbreast: warning: %s\n", fold.c_str());
  if (r.blown_up) {
    std::fprintf(stderr, "voxbreast: error: %s\n", r.message.c_str());
    return 1;
  }
  return 0;
}

}  // namespace

Command add_haptic(CLI::App& app) {
  auto o = std::make_shared<HapticCliOptions>();
  auto* sub = app.add_subcommand("haptic", "Drive a sphere probe along a trajectory in real time; log its force at "
                                           "a haptic rate (haptic.csv, haptic_summary.json)");
  sub->add_option("scene", o->scene, "scene file (TOML) with a sphere [[indenter]]: the probe")
      ->required()->check(CLI::ExistingFile);
  sub->add_option("--trajectory,-t", o->trajectory, "CSV time_s,x_mm,y_mm,z_mm of the probe centre")
      ->required()->check(CLI::ExistingFile);
  sub->add_option("--out,-o", o->out, "output folder")->required();
  sub->add_option("--rate-hz", o->rate_hz, "force outputs per second")->capture_default_str()->check(CLI::Range(1.0, 100000.0));
  sub->add_option("--seconds", o->seconds, "run length (s; default: to the trajectory's end)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--probe", o->probe, "which [[indenter]] is the probe (from 1)")->check(CLI::PositiveNumber);
  sub->add_option("--steps-per-update", o->steps_per_update,
                  "time steps per deformation update (default solver.check_every)")->check(CLI::PositiveNumber);
  sub->add_option("--device,-d", o->device, "OpenCL device: gpu, cpu, an index or a name");
  sub->add_option("--precision", o->precision, "override solver.precision")->check(CLI::IsMember({"float", "double"}));
  sub->add_flag("--no-realtime", o->no_realtime, "keep the output loop at normal priority (default: SCHED_FIFO where allowed)");
  sub->add_flag("--quiet,-q", o->quiet, "no start-up line");
  return {sub, [o] { return run_haptic(*o); }};
}

}  // namespace vb::app
