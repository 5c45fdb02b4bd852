#include "io/run_folder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <system_error>

#include "engine/error.hpp"
#include "io/atomic_file.hpp"
#include "io/system_reason.hpp"
#include "voxbreast/config.hpp"

namespace fs = std::filesystem;

namespace vb {
namespace {

constexpr const char* kStagingPrefix = ".staging-";
constexpr const char* kAsidePrefix = ".replaced-";
/// Written before a commit moves anything, removed after the manifest: the entries of the earlier
/// run and of the one being moved in, so a folder whose commit was killed is still known.
constexpr const char* kPendingName = ".voxbreast-manifest.pending.json";

using Runs = std::map<std::string, std::vector<std::string>>;  // command → entries it wrote

/// A manifest's runs; empty when there is none or it cannot be read (then nothing is known to be
/// VoxBreast's, which only makes the checks stricter).
Runs read_runs(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return {};
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  Runs runs;
  if (!j.is_object() || !j.contains("runs") || !j["runs"].is_object()) return {};
  for (const auto& [command, entries] : j["runs"].items()) {
    if (!entries.is_array()) continue;
    for (const auto& e : entries)
      if (e.is_string()) runs[command].push_back(e.get<std::string>());
  }
  return runs;
}

void write_runs(const fs::path& file, const Runs& runs) {
  nlohmann::json record = {
      {"version", config::version}, {"git_commit", config::git_commit}, {"runs", nlohmann::json::object()}};
  for (const auto& [command, entries] : runs)
    if (!entries.empty()) record["runs"][command] = entries;
  write_text_atomically(file.string(), record.dump(2) + "\n");
}

/// What VoxBreast wrote in `dir`: the manifest, and the pending record of a commit that was cut
/// short (entries of both the earlier and the interrupted run).
Runs recorded_runs(const fs::path& dir) {
  Runs runs = read_runs(dir / kManifestName);
  for (auto& [command, entries] : read_runs(dir / kPendingName)) {
    std::vector<std::string>& all = runs[command];
    for (const std::string& e : entries)
      if (std::find(all.begin(), all.end(), e) == all.end()) all.push_back(e);
  }
  return runs;
}

bool recorded(const Runs& runs, const std::string& entry) {
  return std::any_of(runs.begin(), runs.end(), [&](const auto& run) {
    return std::find(run.second.begin(), run.second.end(), entry) != run.second.end();
  });
}

bool starts_with(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

/// Left by a run that died here: its staging folder, entries moved aside, temporary files, the
/// probe that tests the folder is writable (io/atomic_file.cpp).
bool is_leftover(const std::string& name) {
  return starts_with(name, kStagingPrefix) || starts_with(name, kAsidePrefix) || starts_with(name, ".write-probe-") ||
         (name.size() > 1 && name[0] == '.' && name.find(".tmp-") != std::string::npos);
}

[[noreturn]] void refuse_foreign(const fs::path& dir, const std::string& entry) {
  throw Error("the output folder holds '" + entry + "', which no earlier VoxBreast run recorded writing",
              dir.string(), "move it away or choose another output folder; VoxBreast never replaces files it did not write");
}

}  // namespace

RunFolder::RunFolder(const std::string& dir, const std::string& command, const std::vector<std::string>& always_written)
    : dir_(dir), command_(command) {
  std::error_code ec;
  for (fs::path p = fs::absolute(dir, ec).lexically_normal(); !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    if (p == p.parent_path()) break;
    created_.push_back(p.string());
  }
  try {
    ensure_output_dir(dir_);
    lock_fd_ = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (lock_fd_ < 0) throw Error("cannot open output folder: " + system_reason(errno), dir_);
    if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0)
      throw Error("another VoxBreast run is writing to this output folder", dir_,
                  "wait for it to finish, or choose another --out");
    for (const fs::directory_entry& e : fs::directory_iterator(dir_, ec))  // we hold the lock: all stale
      if (is_leftover(e.path().filename().string())) fs::remove_all(e.path(), ec);
    const Runs runs = recorded_runs(dir_);
    for (const std::string& entry : always_written)
      if (fs::exists(fs::symlink_status(fs::path(dir_) / entry, ec)) && !recorded(runs, entry))
        refuse_foreign(dir_, entry);
    staging_ = (fs::path(dir_) / (kStagingPrefix + std::to_string(::getpid()))).string();
    fs::create_directory(staging_, ec);
    if (ec) throw Error("cannot create the staging folder: " + ec.message(), staging_);
  } catch (...) {  // no destructor runs for a failed constructor
    if (lock_fd_ >= 0) ::close(lock_fd_);
    for (const std::string& p : created_)
      if (!fs::is_directory(p, ec) || !fs::is_empty(p, ec) || !fs::remove(p, ec)) break;
    throw;
  }
}

RunFolder::~RunFolder() {
  std::error_code ec;  // best effort: a destructor must not throw
  if (!staging_.empty()) fs::remove_all(staging_, ec);
  if (!committed_)
    for (const std::string& p : created_)
      if (!fs::is_directory(p, ec) || !fs::is_empty(p, ec) || !fs::remove(p, ec)) break;
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the lock
}

void RunFolder::commit() {
  const fs::path dir(dir_);
  std::error_code ec;
  std::vector<std::string> written;
  for (const fs::directory_entry& e : fs::directory_iterator(staging_, ec)) written.push_back(e.path().filename());
  if (ec) throw Error("cannot list the staging folder: " + ec.message(), staging_);
  std::sort(written.begin(), written.end());

  Runs runs = recorded_runs(dir);
  for (const std::string& entry : written)  // refused before anything moves
    if (fs::exists(fs::symlink_status(dir / entry, ec)) && !recorded(runs, entry)) refuse_foreign(dir, entry);

  Runs pending = runs;
  for (const std::string& entry : written)
    if (!recorded(pending, entry)) pending[command_].push_back(entry);
  write_runs(dir / kPendingName, pending);
  // From here until the new manifest, the folder has none: a reader sees an incomplete folder.
  fs::remove(dir / kManifestName, ec);
  if (ec) throw Error("cannot remove the earlier manifest: " + ec.message(), (dir / kManifestName).string());
  const auto fail = [&](const std::string& what, const std::string& entry) {
    throw Error(what + ": " + ec.message(), (dir / entry).string());
  };
  // The earlier run of this command: what it wrote and this run did not goes.
  for (const std::string& entry : runs[command_])
    if (!std::binary_search(written.begin(), written.end(), entry)) fs::remove_all(dir / entry, ec);
  for (const std::string& entry : written) {
    const fs::path target = dir / entry, from = fs::path(staging_) / entry;
    if (fs::is_directory(fs::symlink_status(target, ec))) {  // a folder is swapped whole
      const fs::path aside = dir / (kAsidePrefix + std::to_string(::getpid()) + "-" + entry);
      fs::rename(target, aside, ec);
      if (ec) fail("cannot move the earlier entry aside", entry);
      fs::rename(from, target, ec);
      if (ec) fail("cannot move the new entry into place", entry);
      fs::remove_all(aside, ec);
    } else {
      fs::rename(from, target, ec);  // replaces a file atomically
      if (ec) fail("cannot move the new entry into place", entry);
    }
  }
  // Other commands' entries stay recorded, less any this run replaced.
  for (auto& [command, entries] : runs)
    std::erase_if(entries, [&](const std::string& e) { return std::binary_search(written.begin(), written.end(), e); });
  runs[command_] = written;
  write_runs(dir / kManifestName, runs);
  fs::remove(dir / kPendingName, ec);
  committed_ = true;
}

}  // namespace vb
