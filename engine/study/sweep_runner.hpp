#pragma once
/// Runs the cases of a sweep that belong to this process: case i belongs to MPI rank
/// i mod ranks; within the process, worker threads (one per device) take the next unfinished case
/// in turn. Each case runs in a hidden working folder that is renamed to cases/NNNN only when
/// complete, so a killed sweep, restarted, skips finished cases and loses none.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "engine/study/sweep_folder.hpp"
#include "engine/study/sweep_grid.hpp"

namespace vb {

struct SweepCase {
  std::size_t index = 0;   ///< 0-based grid position
  std::string id;          ///< "0003"
  std::string scene_text;  ///< the scene with this case's overrides (also written to scene.toml)
  std::string work_dir;    ///< write the outputs here
  std::string final_dir;   ///< where they end up (for paths recorded in the outputs)
};

/// Runs one case, writing summary.json (and other outputs) into case.work_dir. An exception
/// fails the case, and its message is recorded; the sweep goes on.
using SweepCaseRunner = std::function<void(const SweepCase& c, std::size_t worker)>;

struct SweepProgress {
  enum class Kind { Started, Finished };
  Kind kind = Kind::Started;
  std::size_t index = 0;
  std::string id;
  std::size_t worker = 0;
  std::string status, error;  ///< Finished: "ok" | "failed", and the error
  double wall_time_s = 0;     ///< Finished: the case's wall time (s)
  std::size_t done = 0;       ///< cases of this process finished so far (also earlier runs)
  std::size_t total = 0;      ///< cases of this process
};

struct SweepRunOptions {
  int rank = 0, ranks = 1;
  std::vector<std::string> workers = {"worker"};  ///< one name (its device) per worker thread
  std::size_t stop_after = 0;  ///< run at most this many cases, then stop (0: all)
  bool retry_failed = false;   ///< run failed cases again
  /// Called from worker threads, one call at a time.
  std::function<void(const SweepProgress&)> on_progress;
};

struct SweepRunReport {
  std::size_t owned = 0;     ///< cases of this process
  std::size_t skipped = 0;   ///< finished before this run
  std::size_t ran = 0, failed = 0;
  std::size_t left = 0;      ///< not finished when this run stopped (stop_after)
};

/// Runs this process's unfinished cases; case_scenes[i] is case i's scene text. Throws vb::Error
/// when the folder cannot be written (case failures are recorded, not thrown).
SweepRunReport run_sweep_cases(const SweepFolder& folder, const SweepGrid& grid,
                               const std::vector<std::string>& case_scenes, const SweepCaseRunner& run_case,
                               const SweepRunOptions& options);

}  // namespace vb
