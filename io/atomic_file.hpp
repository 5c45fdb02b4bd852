#pragma once
/// Outputs are written under a hidden temporary name next to the final file and renamed into
/// place, so a reader never sees a half-written file and a failed run leaves no debris.
#include <string>
#include <vector>

namespace vb {

class AtomicOutput {
 public:
  /// final_path: where the file will appear on commit(); its directory must already exist.
  explicit AtomicOutput(std::string final_path);
  /// Removes the temporary file unless commit() succeeded; never throws.
  ~AtomicOutput();

  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  /// Same directory as the final path, e.g. `.result.h5.tmp-<pid>-<counter>`; write here.
  const std::string& temp_path() const { return temp_path_; }
  const std::string& final_path() const { return final_path_; }

  /// Renames the temporary file onto the final path (replacing it); throws vb::Error on failure.
  void commit();

 private:
  std::string final_path_;
  std::string temp_path_;
  bool committed_ = false;
};

/// Creates `dir` (and parents) and checks that a file can be created in it; throws vb::Error
/// "cannot write to output folder 'dir': <reason>" otherwise.
void ensure_output_dir(const std::string& dir);

/// A command's output folder: the constructor calls ensure_output_dir (before any computing, so
/// that an unwritable folder fails fast); the destructor removes the folders the constructor
/// created, innermost first, while they are empty, so a command that fails before writing
/// anything leaves no empty folder behind. Folders that existed before are never removed.
class OutputDir {
 public:
  explicit OutputDir(const std::string& dir);
  ~OutputDir();  ///< best effort; never throws

  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

 private:
  void remove_empty_created() const noexcept;

  std::vector<std::string> created_;  // innermost first
};

/// Writes `text` to `path` through an AtomicOutput; throws vb::Error on failure.
void write_text_atomically(const std::string& path, const std::string& text);

}  // namespace vb
