#pragma once
/// A parameter sweep (docs/SWEEP.md): the scene run once per point of a grid of scene-key
/// values, resumable, spread over devices and MPI ranks, tabulated in metrics.csv.
#include <functional>
#include <string>
#include <vector>

#include "engine/study/mpi_world.hpp"
#include "engine/study/sweep_grid.hpp"
#include "engine/study/sweep_runner.hpp"
#include "engine/study/sweep_tables.hpp"

namespace vb {

struct SweepPlan {
  std::string scene_path;                ///< the base scene file
  std::string scene_text;                ///< its text
  SweepGrid grid{{}};
  std::vector<std::string> case_scenes;  ///< scene text of each case
  std::vector<std::string> input_files;  ///< every data file or folder the cases' scenes name, sorted
};

/// Reads the scene and builds every case's scene text: the base text with the case's overrides,
/// relative data paths made absolute (against the base scene's folder) so each case folder's
/// scene.toml runs on its own. Each case scene goes through the strict scene parser here, so a
/// bad key or value stops the sweep before any case runs (vb::Error naming the case).
SweepPlan plan_sweep(const std::string& scene_path, std::vector<SweepParameter> parameters);

struct SweepOptions {
  std::string out_dir;
  std::string outputs = "minimal";  ///< "minimal" | "full": recorded in sweep.json
  std::size_t stop_after = 0;       ///< per process: run at most this many cases (0: all)
  bool retry_failed = false;
  std::vector<std::string> workers = {"worker"};  ///< this process's workers (device names)
  std::function<void(const SweepProgress&)> on_progress;
};

struct SweepOutcome {
  SweepRunReport run;                 ///< this process's share
  SweepTablesReport tables;           ///< the whole sweep (rank 0 only)
  std::vector<std::string> warnings;  ///< e.g. finished cases from another build
};

/// Runs the plan as rank world.rank() of world.size(): rank 0 takes the folder's lock and
/// creates or checks sweep.json; every rank runs its cases; after all have finished (or
/// failed), rank 0 writes metrics.csv and timing.csv. Throws vb::Error when this or another
/// rank could not run its cases.
SweepOutcome run_sweep(const SweepPlan& plan, const SweepOptions& options, const MpiWorld& world,
                       const SweepCaseRunner& run_case);

}  // namespace vb
