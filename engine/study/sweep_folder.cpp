#include "engine/study/sweep_folder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>

#include "engine/error.hpp"
#include "io/atomic_file.hpp"
#include "voxbreast/config.hpp"

namespace fs = std::filesystem;

namespace vb {
namespace {

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open file", path, "check the sweep folder");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(std::string("not valid JSON: ") + e.what(), path, "remove the file or the sweep folder");
  }
}

/// The first difference between two definitions, in words; empty when equal.
std::string difference(const nlohmann::json& was, const nlohmann::json& now) {
  if (was.value("scene", "") != now.value("scene", "")) return "the scene file (" + was.value("scene", "") + ")";
  if (was.value("scene_text", "") != now.value("scene_text", "")) return "the scene file's text has changed";
  if (was.value("outputs", "") != now.value("outputs", ""))
    return "--outputs (" + was.value("outputs", "") + ", now " + now.value("outputs", "") + ")";
  const nlohmann::json a = was.value("parameters", nlohmann::json::array());
  const nlohmann::json& b = now["parameters"];
  for (std::size_t i = 0; i < std::max(a.size(), b.size()); ++i) {
    if (i >= a.size()) return "--vary " + b[i].value("key", "") + " is new";
    if (i >= b.size()) return "--vary " + a[i].value("key", "") + " is missing";
    if (a[i].value("key", "") != b[i].value("key", "") || a[i].value("add", false) != b[i].value("add", false))
      return "--vary " + std::to_string(i + 1) + " was " + (a[i].value("add", false) ? "+" : "") + a[i].value("key", "");
    if (a[i] != b[i])
      return "--vary " + a[i].value("key", "") + " had the values " + a[i]["values"].dump() + ", now " + b[i]["values"].dump();
  }
  if (was.contains("inputs")) {
    const nlohmann::json& before = was["inputs"];
    const nlohmann::json after = now.value("inputs", nlohmann::json::object());
    for (const auto& [file, hash] : after.items())
      if (before.contains(file) && before[file] != hash)
        return "the input file " + file + " has changed since the sweep started (its SHA-256 differs)";
  }
  nlohmann::json compared = now;  // a sweep.json from before input hashes were recorded has none
  if (!was.contains("inputs")) compared.erase("inputs");
  return was == compared ? "" : "sweep.json differs";
}

}  // namespace

nlohmann::json sweep_definition(const SweepGrid& grid, const std::string& scene_path, const std::string& scene_text,
                                const std::string& outputs) {
  nlohmann::json parameters = nlohmann::json::array();
  for (const SweepParameter& p : grid.parameters())
    parameters.push_back({{"key", p.key}, {"add", p.add}, {"values", p.values}});
  return {{"scene", fs::weakly_canonical(fs::absolute(scene_path)).string()},
          {"scene_text", scene_text},
          {"outputs", outputs},
          {"parameters", parameters},
          {"cases", grid.size()}};
}

SweepFolder::SweepFolder(std::string dir, std::size_t case_count)
    : dir_(std::move(dir)), case_count_(case_count), digits_(std::max<int>(4, int(std::to_string(case_count).size()))) {}

std::string SweepFolder::case_id(std::size_t index) const {
  std::string id = std::to_string(index + 1);
  return std::string(std::size_t(digits_) - std::min(id.size(), std::size_t(digits_)), '0') + id;
}

std::string SweepFolder::case_dir(std::size_t index) const { return path("cases/" + case_id(index)); }

std::vector<std::string> SweepFolder::open(const nlohmann::json& definition) const {
  ensure_output_dir(dir_);
  ensure_output_dir(path("cases"));
  const std::string file = path("sweep.json");
  nlohmann::json record = definition;
  record["version"] = config::version;
  record["git_commit"] = config::git_commit;
  if (!fs::exists(file)) {
    // A new sweep: the names it writes must not be someone else's files (never replaced).
    std::error_code ec;
    for (const char* name : {"metrics.csv", "timing.csv", "plots"})
      if (fs::exists(fs::symlink_status(path(name), ec)))
        throw Error(std::string("the output folder holds '") + name + "', which is not a VoxBreast sweep's (no sweep.json)",
                    dir_, "move it away or choose another --out");
    // Another rank or worker of this sweep may already be writing its first case (in its
    // work folder .NNNN.work-…) before sweep.json lands: that name is the sweep's own.
    static const std::regex own_case(R"(\.[0-9]+\.work-.*)");
    for (const fs::directory_entry& e : fs::directory_iterator(path("cases"), ec))
      if (!std::regex_match(e.path().filename().string(), own_case))
        throw Error("the output folder's cases/ holds '" + e.path().filename().string() +
                        "', which is not a VoxBreast sweep's (no sweep.json)",
                    dir_, "move it away or choose another --out");
    write_text_atomically(file, record.dump(2) + "\n");
    return {};
  }
  nlohmann::json was = read_json(file);
  const std::string built_by = was.value("git_commit", "");
  was.erase("version");
  was.erase("git_commit");
  if (const std::string diff = difference(was, definition); !diff.empty())
    throw Error("the folder holds another sweep: " + diff, file,
                "rerun with the same scene and options to continue it, or choose a new --out");
  if (built_by != config::git_commit)
    return {"the finished cases in " + dir_ + " were computed by build " + built_by + ", this is " +
            config::git_commit};
  return {};
}

SweepFolder::Lock::Lock(const std::string& path) {
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw Error(std::string("cannot create the lock file: ") + std::strerror(errno), path);
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd_);
    throw Error("another sweep is running in this folder", path, "wait for it to finish, or choose another --out");
  }
}

SweepFolder::Lock::~Lock() {
  if (fd_ >= 0) ::close(fd_);  // closing releases the lock
}

bool SweepFolder::is_finished(std::size_t index) const {
  return fs::is_regular_file(case_dir(index) + "/case.json");
}

SweepCaseRecord SweepFolder::read_record(std::size_t index) const {
  const std::string file = case_dir(index) + "/case.json";
  const nlohmann::json j = read_json(file);
  SweepCaseRecord r;
  try {
    r.index = index;
    r.status = j.at("status").get<std::string>();
    r.error = j.value("error", "");
    r.rank = j.value("rank", 0);
    r.worker = j.value("worker", std::size_t(0));
    r.device = j.value("device", "");
    r.wall_time_s = j.value("wall_time_s", 0.0);
  } catch (const nlohmann::json::exception& e) {
    throw Error(std::string("unexpected content: ") + e.what(), file, "remove this case folder to run the case again");
  }
  return r;
}

void SweepFolder::remove_leftovers(const std::function<bool(std::size_t)>& owned) const {
  std::error_code ec;
  std::vector<fs::path> leftovers;
  for (const fs::directory_entry& e : fs::directory_iterator(path("cases"), ec)) {
    const std::string name = e.path().filename().string();
    // Only the names this class makes (.0003.work-r0-p123, .0003.old-p123): a folder of someone
    // else's that merely starts like one is never removed.
    static const std::regex ours(R"(\.([0-9]+)\.(work-r[0-9]+-p[0-9]+|old-p[0-9]+))");
    std::smatch match;
    if (!std::regex_match(name, match, ours)) continue;
    const std::size_t id = std::strtoull(match[1].str().c_str(), nullptr, 10);
    if (id >= 1 && id <= case_count_ && owned(id - 1)) leftovers.push_back(e.path());
  }
  for (const fs::path& p : leftovers) fs::remove_all(p, ec);
}

std::string SweepFolder::make_work_dir(std::size_t index, int rank) const {
  const std::string work =
      path("cases/." + case_id(index) + ".work-r" + std::to_string(rank) + "-p" + std::to_string(::getpid()));
  std::error_code ec;
  fs::remove_all(work, ec);
  ensure_output_dir(work);
  return work;
}

void SweepFolder::commit(const std::string& work_dir, const SweepCaseRecord& r, const nlohmann::json& values) const {
  const nlohmann::json j = {{"case", case_id(r.index)}, {"values", values},   {"status", r.status},
                            {"error", r.error},         {"rank", r.rank},     {"worker", r.worker},
                            {"device", r.device},       {"wall_time_s", r.wall_time_s}};
  write_text_atomically(work_dir + "/case.json", j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  const std::string final_dir = case_dir(r.index);
  std::error_code ec;
  if (fs::exists(final_dir)) {  // a retried case: move the old result aside first, then drop it
    const std::string old = path("cases/." + case_id(r.index) + ".old-p" + std::to_string(::getpid()));
    fs::rename(final_dir, old, ec);
    if (ec) throw Error("cannot move the previous result aside: " + ec.message(), final_dir);
    fs::rename(work_dir, final_dir, ec);
    if (!ec) fs::remove_all(old, ec);
    ec.clear();
  } else {
    fs::rename(work_dir, final_dir, ec);
  }
  if (ec || !fs::exists(final_dir)) throw Error("cannot rename the finished case into place: " + ec.message(), final_dir);
}

}  // namespace vb
