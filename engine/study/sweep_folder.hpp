#pragma once
/// The folder of a sweep (docs/SWEEP.md, "Folder"):
///   DIR/sweep.json          what the sweep is (scene, grid, outputs); a restart must match it
///   DIR/cases/NNNN/         one finished case: scene.toml, case.json, summary.json, outputs
///   DIR/cases/.NNNN.work-*  a case being run (renamed to NNNN when complete, so a folder named
///                           NNNN is always complete; leftovers of killed runs are removed)
///   DIR/metrics.csv, DIR/timing.csv, DIR/sweep_log.jsonl, DIR/plots/
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/study/sweep_grid.hpp"

namespace vb {

/// What a finished case records in its case.json.
struct SweepCaseRecord {
  std::size_t index = 0;           ///< 0-based position in the grid
  std::string status;              ///< "ok" or "failed"
  std::string error;               ///< the error message of a failed case
  int rank = 0;                    ///< MPI rank that ran it
  std::size_t worker = 0;          ///< worker (device) within that rank
  std::string device;              ///< OpenCL device name
  double wall_time_s = 0;          ///< whole case: model, run and outputs (s)
};

/// sweep.json's content: the scene (path and text), the grid and the outputs mode. Two sweeps
/// with equal definitions compute the same cases.
nlohmann::json sweep_definition(const SweepGrid& grid, const std::string& scene_path, const std::string& scene_text,
                                const std::string& outputs);

class SweepFolder {
 public:
  SweepFolder(std::string dir, std::size_t case_count);

  const std::string& dir() const { return dir_; }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  std::size_t case_count() const { return case_count_; }

  /// "0001" … : 1-based, at least 4 digits, all of one width.
  std::string case_id(std::size_t index) const;
  std::string case_dir(std::size_t index) const;

  /// Creates DIR and sweep.json, or checks that the sweep.json there has this definition:
  /// vb::Error naming the first difference otherwise. Returns warnings (e.g. another build).
  std::vector<std::string> open(const nlohmann::json& definition) const;

  /// Holds DIR/.lock (flock) while alive, so two sweeps cannot run into one folder at once.
  class Lock {
   public:
    explicit Lock(const std::string& path);
    ~Lock();
    Lock(const Lock&) = delete;
    Lock& operator=(const Lock&) = delete;

   private:
    int fd_ = -1;
  };
  Lock lock() const { return Lock(path(".lock")); }

  /// true when cases/NNNN exists (complete by construction).
  bool is_finished(std::size_t index) const;
  SweepCaseRecord read_record(std::size_t index) const;

  /// Removes what killed runs left (hidden .NNNN.* folders) of the cases `owned` says are this
  /// process's; one listing of cases/ for all of them.
  void remove_leftovers(const std::function<bool(std::size_t)>& owned) const;
  /// A new, empty working folder for case `index` in process `rank`.
  std::string make_work_dir(std::size_t index, int rank) const;
  /// Writes case.json into the working folder and renames it to cases/NNNN (replacing a
  /// finished case, e.g. a failed one being retried).
  /// `values`: the case's parameter values (key → value), kept in case.json for readers.
  void commit(const std::string& work_dir, const SweepCaseRecord& record, const nlohmann::json& values) const;

 private:
  std::string dir_;
  std::size_t case_count_;
  int digits_;
};

}  // namespace vb
