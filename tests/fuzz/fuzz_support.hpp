#pragma once
// What both fuzz targets share: a private work folder and an opt-in trace.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

namespace vb::fuzz {

/// True when VB_FUZZ_VERBOSE is set: each call's outcome is printed, for replaying one input.
inline bool verbose() {
  static const bool on = std::getenv("VB_FUZZ_VERBOSE") != nullptr;
  return on;
}

/// One private folder per process under $TMPDIR (or /tmp), named after `target`, removed at exit.
/// The first call fixes the folder; a fuzz binary has one target.
inline const std::filesystem::path& work_dir(const char* target) {
  // Never destroyed, so that the atexit handler can still use it at exit.
  static const std::filesystem::path& dir = *new std::filesystem::path([target] {
    const char* base = std::getenv("TMPDIR");
    std::string pattern = std::string(base && *base ? base : "/tmp") + "/vb-fuzz-" + target + "-XXXXXX";
    if (!::mkdtemp(pattern.data())) {
      std::perror("fuzz: mkdtemp");
      std::abort();
    }
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(work_dir(""), ignored);
    });
    return pattern;
  }());
  return dir;
}

}  // namespace vb::fuzz
