// voxbreast probe SCENE.toml --out DIR — settles the model under gravity, then runs the scene's
// [probe] line of quasi-static presses; writes probe_curves.csv, probe_profile.csv and
// probe_summary.json (docs/OUTPUTS.md). Plots: scripts/plot_probe.py DIR.
//   voxbreast probe data-samples/palpation/scene.toml --out out/palpation
#include <cstdio>
#include <memory>

#include "apps/commands.hpp"
#include "apps/simulation_setup.hpp"
#include "engine/error.hpp"
#include "engine/probe/press_line.hpp"
#include "io/atomic_file.hpp"
#include "io/probe_outputs.hpp"

namespace vb::app {
namespace {

struct ProbeOptions {
  std::string scene, out, device, precision;
  bool quiet = false;
};

int run_probe(const ProbeOptions& o) {
  const Scene scene = load_scene(o.scene, o.precision);
  require(scene.probe.active, "the scene has no [probe] section", o.scene, "add [probe] (docs/SCENE.md)");
  const OutputDir output_dir(o.out);
  const ClContext cl(select_device(o.device));
  const PreparedModel model = prepare_model(scene, &cl.info);
  Simulator sim(scene, model.lattice, model.elements, cl);
  if (!o.quiet)
    std::fprintf(stderr, "voxbreast: %zu elements, dt = %.3g s, device %s; %d presses of %d increments\n",
                 model.lattice.element_count(), sim.dt_s(), cl.info.name.c_str(), scene.probe.presses, scene.probe.steps);
  const ProbeProgress progress = [&](int press, int increment, double residual) {
    if (o.quiet) return;
    if (press < 0) std::fprintf(stderr, "voxbreast: settled (residual %.2e)\n", residual);
    else if (increment == scene.probe.steps) std::fprintf(stderr, "voxbreast: press %d done (residual %.2e)\n", press + 1, residual);
  };
  const ProbeResult r = run_press_line(scene, model.lattice, model.elements, sim, progress);
  write_probe_outputs(o.out, scene, r);
  for (std::size_t k = 0; k < r.presses.size(); ++k)
    std::printf("press %zu at %.2f mm: force %.4g N at %.3g mm, stiffness %.4g N/mm\n", k + 1, 1e3 * r.presses[k].position_m,
                r.presses[k].peak_force_n, 1e3 * scene.probe.depth_m, 1e-3 * r.presses[k].stiffness_n_m);
  if (!r.settled)
    std::fprintf(stderr, "voxbreast: warning: settling under gravity stopped at stop.max_steps before equilibrium\n");
  if (r.unconverged_increments > 0)
    std::fprintf(stderr, "voxbreast: warning: %lld increments stopped at stop.max_steps before equilibrium\n",
                 (long long)r.unconverged_increments);
  for (std::size_t k = 0; k < r.presses.size(); ++k)
    if (r.presses[k].inverted)
      std::fprintf(stderr,
                   "voxbreast: warning: press %zu folded the lattice (det F = %.3g <= 0 under the indenter): its force is "
                   "not physical; press less deep, or use a hyperelastic law (docs/PROBING.md, \"Validity\")\n",
                   k + 1, r.presses[k].min_det_f);
  std::printf("%lld steps in %.1f s\nwrote %s/probe_curves.csv, probe_profile.csv, probe_summary.json\n",
              (long long)r.total_steps, r.wall_time_s, o.out.c_str());
  // Without an equilibrium test every increment runs its steps, as asked.
  if (!(scene.stop.equilibrium > 0) || (r.settled && r.unconverged_increments == 0)) return 0;
  std::fprintf(stderr, "voxbreast: the curves are not converged (see the warnings above); exit status %d\n",
               kExitNotConverged);
  return kExitNotConverged;
}

}  // namespace

Command add_probe(CLI::App& app) {
  auto o = std::make_shared<ProbeOptions>();
  auto* sub = app.add_subcommand("probe", "Settle, then run the scene's [probe] line of presses; write force curves and the profile");
  sub->add_option("scene", o->scene, "scene file (TOML) with a [probe] section")->required()->check(CLI::ExistingFile);
  sub->add_option("--out,-o", o->out, "output folder")->required();
  sub->add_option("--device,-d", o->device, "OpenCL device: gpu, cpu, an index or a name (default $VOXBREAST_DEVICE, else first GPU)");
  sub->add_option("--precision", o->precision, "override solver.precision")->check(CLI::IsMember({"float", "double"}));
  sub->add_flag("--quiet,-q", o->quiet, "no progress messages");
  return {sub, [o] { return run_probe(*o); }};
}

}  // namespace vb::app
