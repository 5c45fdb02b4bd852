#include "apps/sweep_plots.hpp"

#include <spawn.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <vector>

#include "voxbreast/config.hpp"

extern char** environ;

namespace vb::app {

namespace {

/// Runs `python3 SCRIPT DIR` (the script from $env_var, else scripts/NAME in the source tree);
/// returns "" on success, else a line saying what happened and how to draw the plot by hand.
std::string run_plot_script(const char* env_var, const std::string& name, const std::string& sweep_dir) {
  const char* env = std::getenv(env_var);
  const std::string script = env ? env : std::string(config::source_dir) + "/scripts/" + name;
  const std::string by_hand = "draw them with: python3 scripts/" + name + " " + sweep_dir;
  if (!std::filesystem::is_regular_file(script)) return "plots: " + script + " not found; " + by_hand;
  // Debian's interpreter first: it has python3-matplotlib (scripts/setup.sh); else the PATH's.
  const std::string python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  std::vector<std::string> args = {python, script, sweep_dir};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, python.c_str(), nullptr, nullptr, argv.data(), environ) != 0)
    return "plots: python3 not found; " + by_hand;
  int status = 0;
  if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status)) return "plots: the plot script did not finish; " + by_hand;
  if (WEXITSTATUS(status) == 0) return "";  // the script says what it wrote
  if (WEXITSTATUS(status) == 77) return "plots: skipped (matplotlib missing); " + by_hand;
  return "plots: the plot script failed (exit " + std::to_string(WEXITSTATUS(status)) + "); " + by_hand;
}

}  // namespace

std::string draw_sweep_plots(const std::string& sweep_dir) {
  return run_plot_script("VOXBREAST_PLOT_SWEEP", "plot_sweep.py", sweep_dir);
}

std::string draw_fit_plot(const std::string& fit_dir) { return run_plot_script("VOXBREAST_PLOT_FIT", "plot_fit.py", fit_dir); }

}  // namespace vb::app
