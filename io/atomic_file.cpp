#include "io/atomic_file.hpp"
#include "io/system_reason.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "engine/error.hpp"

namespace fs = std::filesystem;

namespace vb {
namespace {

/// Unique within the process (counter) and across processes sharing a folder (pid).
std::string unique_suffix() {
  static std::atomic<unsigned long> counter{0};
  return std::to_string(::getpid()) + "-" + std::to_string(counter++);
}

std::string temp_path_for(const std::string& final_path) {
  const fs::path final(final_path);
  return (final.parent_path() / ("." + final.filename().string() + ".tmp-" + unique_suffix()))
      .string();
}

[[noreturn]] void fail_output_dir(const std::string& dir, const std::string& reason) {
  throw Error("cannot write to output folder '" + dir + "': " + reason, {},
              "choose another output folder or fix its permissions");
}

}  // namespace

AtomicOutput::AtomicOutput(std::string final_path)
    : final_path_(std::move(final_path)), temp_path_(temp_path_for(final_path_)) {}

AtomicOutput::~AtomicOutput() {
  if (committed_) return;
  std::error_code ignored;  // best effort: a destructor must not throw
  fs::remove(temp_path_, ignored);
}

void AtomicOutput::commit() {
  std::error_code ec;
  fs::rename(temp_path_, final_path_, ec);
  if (ec)
    throw Error("cannot rename '" + temp_path_ + "' to '" + final_path_ + "': " + ec.message(),
                final_path_);
  committed_ = true;
}

void ensure_output_dir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) fail_output_dir(dir, ec.message());
  if (!fs::is_directory(dir, ec)) fail_output_dir(dir, "not a directory");

  // Permission bits do not tell the whole story (read-only mounts, ACLs): try it.
  const std::string probe = (fs::path(dir) / (".write-probe-" + unique_suffix())).string();
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
  if (fd < 0) fail_output_dir(dir, std::strerror(errno));
  ::close(fd);
  fs::remove(probe, ec);
}

OutputDir::OutputDir(const std::string& dir) {
  std::error_code ec;
  for (fs::path p = fs::absolute(dir, ec).lexically_normal(); !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    if (p == p.parent_path()) break;  // the root
    created_.push_back(p.string());
  }
  try {
    ensure_output_dir(dir);
  } catch (...) {  // created, then found unwritable: no destructor runs for a failed constructor
    remove_empty_created();
    throw;
  }
}

OutputDir::~OutputDir() { remove_empty_created(); }

void OutputDir::remove_empty_created() const noexcept {
  std::error_code ec;  // fs::remove deletes a folder only when it is empty; errors are ignored
  for (const std::string& p : created_)
    if (!fs::is_directory(p, ec) || !fs::is_empty(p, ec) || !fs::remove(p, ec)) break;
}

std::string system_reason(int errnum) {
  std::string reason = std::strerror(errnum);
  if (!reason.empty()) reason[0] = char(std::tolower(static_cast<unsigned char>(reason[0])));
  return reason;
}

void write_text_atomically(const std::string& path, const std::string& text) {
  AtomicOutput out(path);
  std::FILE* f = std::fopen(out.temp_path().c_str(), "wb");
  if (!f) throw Error("cannot create file: " + system_reason(errno), path);
  const bool written = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const int write_errno = errno;
  // fclose flushes the buffer, so its failure (e.g. disk full) is a write failure too.
  const bool closed = std::fclose(f) == 0;
  if (!written || !closed)
    throw Error("cannot write file: " + system_reason(written ? errno : write_errno), path);
  out.commit();
}

}  // namespace vb
