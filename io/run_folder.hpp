#pragma once
/// A command's output folder, written whole. The run writes into a hidden staging folder inside
/// it; only when everything is written are the files moved into place, the earlier run's record
/// (its manifest) removed first and the new one written last, so that a folder with a manifest
/// holds exactly one complete run (docs/OUTPUTS.md, "How files are written").
#include <string>
#include <vector>

namespace vb {

/// The manifest's name inside an output folder: JSON with the command and the entries it wrote.
inline constexpr const char* kManifestName = ".voxbreast-manifest.json";

class RunFolder {
 public:
  /// Creates `dir` (and parents) when needed, checks that it is writable, takes its lock (an
  /// exclusive flock on the folder, released when the process ends, also by a kill: a second
  /// writer is refused), removes what runs that died there left (staging folders and temporary
  /// files), and makes the staging folder. `command` names the writer in the manifest.
  /// `always_written`: entries the command writes on every run; one that exists and no earlier
  /// VoxBreast run recorded is refused now, before any computing.
  RunFolder(const std::string& dir, const std::string& command, const std::vector<std::string>& always_written);
  /// Without commit(): removes the staging folder, and the folders the constructor created while
  /// they are empty; an earlier run's files stay as they were. Never throws.
  ~RunFolder();

  RunFolder(const RunFolder&) = delete;
  RunFolder& operator=(const RunFolder&) = delete;

  const std::string& path() const { return dir_; }
  /// Where the run writes its files and folders (hidden, inside path()).
  const std::string& staging() const { return staging_; }

  /// Moves the staging folder's entries into path(). An entry of the same name is replaced only
  /// when the earlier run's manifest lists it (a folder is swapped whole); anything else there is
  /// refused (vb::Error), before anything moves. The earlier manifest is removed before the first
  /// move, the entries the earlier run of this command wrote and this one did not are removed, and
  /// the new manifest is written last.
  void commit();

 private:
  std::string dir_, command_, staging_;
  std::vector<std::string> created_;  // folders the constructor created, innermost first
  int lock_fd_ = -1;
  bool committed_ = false;
};

}  // namespace vb
