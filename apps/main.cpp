// voxbreast — CT-based, GPU-simulated breast biomechanics.
//
// Usage:
//   voxbreast info
//   voxbreast simulate data-samples/breast_phantom.toml --out out/phantom
//   voxbreast sweep data-samples/phantom/scene.toml --vary gravity.posture=prone,supine --out out/sweep
//   voxbreast bench --quick --out out/bench
//   voxbreast haptic scene.toml --trajectory press.csv --rate-hz 1000 --out out/haptic
//   voxbreast probe data-samples/palpation/scene.toml --out out/palpation
//   voxbreast cache --clear
//   voxbreast export data-samples/phantom/scene.toml --feb out/phantom.feb
//   voxbreast view out/phantom
//   voxbreast serve data-samples/phantom/scene.toml
// Every subcommand has --help. Errors print one line naming the problem and exit non-zero (2 for
// a misused command line, 4 for a run that went unstable or
// cannot keep its contact, 1 for everything else; simulate exits 3
// when its result is not converged).
#include <CL/opencl.hpp>
#include <cstdio>

#include "apps/commands.hpp"
#include "apps/program_cache_folder.hpp"
#include "engine/error.hpp"
#include "engine/sim/instability.hpp"
#include "engine/sim/contact_checks.hpp"
#include "engine/sim/opencl_runtime.hpp"
#include "engine/sim/program_cache.hpp"
#include "voxbreast/config.hpp"

int main(int argc, char** argv) {
  CLI::App app{"VoxBreast: voxel-lattice breast biomechanics on OpenCL devices"};
  app.set_version_flag("--version", std::string(vb::config::version) + " (" + vb::config::git_commit + ")");
  app.require_subcommand(1);
  const vb::app::Command commands[] = {vb::app::add_info(app), vb::app::add_simulate(app),
                                       vb::app::add_bench(app), vb::app::add_phantom(app),
                                       vb::app::add_sweep(app), vb::app::add_haptic(app),
                                       vb::app::add_fit_curve(app), vb::app::add_probe(app), vb::app::add_fit(app),
                                       vb::app::add_cache(app), vb::app::add_export(app),
                                       vb::app::add_view(app), vb::app::add_serve(app)};
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // A usage error in the same one-line form as every other error, with the help to read.
    std::string command = "voxbreast";
    for (const CLI::App* sub : app.get_subcommands()) command += " " + sub->get_name();
    std::fprintf(stderr, "voxbreast: error: %s (see '%s --help')\n", e.what(), command.c_str());
    return 2;
  }
  vb::set_program_cache_dir(vb::app::program_cache_folder());
  try {
    for (const auto& command : commands)
      if (command.sub->parsed()) return command.run();
  } catch (const vb::InstabilityError& e) {
    std::fprintf(stderr, "voxbreast: error: %s\n", e.what());
    return vb::app::kExitUnstable;
  } catch (const vb::ContactError& e) {
    std::fprintf(stderr, "voxbreast: error: %s\n", e.what());
    return vb::app::kExitUnstable;
  } catch (const vb::Error& e) {
    std::fprintf(stderr, "voxbreast: error: %s\n", e.what());
    return 1;
  } catch (const cl::Error& e) {
    std::fprintf(stderr, "voxbreast: error: OpenCL call %s failed: %s\n", e.what(),
                 vb::cl_status_name(e.err()).c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "voxbreast: error: %s\n", e.what());
    return 1;
  }
  return 1;
}
