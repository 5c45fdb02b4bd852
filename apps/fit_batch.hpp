#pragma once
/// `voxbreast fit --cases CASES.csv --out DIR`: one fit per scene of a CSV, run by the sweep
/// runner (engine/study/sweep.hpp) across OpenCL devices and MPI ranks; resumable at two levels
/// (finished cases are kept; a case's iterations are checkpointed in DIR/progress/NNNN).
/// Folder: DIR/cases/NNNN/ (the fit's outputs), DIR/metrics.csv (one row per case: the scalars
/// of its summary.json), DIR/timing.csv. docs/FIT.md, "Batch".
#include <string>

namespace vb::app {

struct FitBatchOptions {
  std::string cases_csv, out, devices;
  std::size_t stop_after = 0;  ///< cases per process, then stop (resumable)
  bool retry_failed = false, quiet = false, plots = true;
};

/// Exit code: 0 all cases done, 3 some not run yet (--stop-after). Failed cases are recorded in
/// metrics.csv (status failed) and make the exit code 4.
int run_fit_batch(const FitBatchOptions& options);

}  // namespace vb::app
