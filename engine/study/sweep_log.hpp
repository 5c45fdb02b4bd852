#pragma once
/// DIR/sweep_log.jsonl: one JSON object per line for each event of a sweep (start, case start,
/// case end, stop), appended as it happens by every process of the sweep, for monitoring tools.
#include <nlohmann/json.hpp>
#include <string>

namespace vb {

class SweepLog {
 public:
  explicit SweepLog(std::string path) : path_(std::move(path)) {}
  /// Appends `event` with "time" (UTC, ISO 8601) in one write(2) to a file opened O_APPEND, so
  /// lines from threads and MPI ranks on one machine do not interleave. Never throws: the log
  /// must not stop a sweep.
  void append(nlohmann::json event) const;

 private:
  std::string path_;
};

}  // namespace vb
