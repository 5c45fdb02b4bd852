#pragma once
/// The voxbreast subcommands: each registers its options on the CLI and runs when chosen.
#include <CLI/CLI.hpp>
#include <functional>

namespace vb::app {

/// Exit statuses besides 0 (done as asked), 1 (an error) and 2 (a misused command line):
/// a result that is not converged (written, and flagged in its summary), and a run that went
/// unstable (nothing written). README.md, "Exit status".
inline constexpr int kExitNotConverged = 3, kExitUnstable = 4;

/// A registered subcommand and what runs it (after parsing); run returns the exit code.
struct Command {
  CLI::App* sub = nullptr;
  std::function<int()> run;
};

Command add_info(CLI::App& app);
Command add_simulate(CLI::App& app);
Command add_bench(CLI::App& app);
Command add_phantom(CLI::App& app);
Command add_sweep(CLI::App& app);
Command add_haptic(CLI::App& app);
Command add_fit_curve(CLI::App& app);
Command add_probe(CLI::App& app);
Command add_fit(CLI::App& app);
Command add_cache(CLI::App& app);
Command add_export(CLI::App& app);
Command add_view(CLI::App& app);
Command add_serve(CLI::App& app);

}  // namespace vb::app
