// RunFolder: an output folder holds one complete run or says it does not (no manifest), a second
// writer is refused, leftovers of killed runs go, and files VoxBreast did not write stay.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <string>
#include <thread>

#include "engine/error.hpp"
#include "io/atomic_file.hpp"
#include "io/run_folder.hpp"

namespace fs = std::filesystem;

namespace vb {
namespace {

class RunFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    root_ = fs::temp_directory_path() / ("voxbreast-run-folder-" + std::to_string(::getpid()) + "-" + test->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
    dir_ = root_ / "out";
  }
  void TearDown() override { fs::remove_all(root_); }

  static std::string text_of(const fs::path& file) {
    std::ifstream in(file);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  static void write(const fs::path& file, const std::string& text) { std::ofstream(file) << text; }

  /// One run: three files and a folder of two, each holding the run's tag, then the commit.
  void run(const std::string& tag, bool with_extra = false) const {
    RunFolder folder(dir_.string(), "simulate", {"summary.json"});
    const fs::path s = folder.staging();
    write_text_atomically((s / "metrics.csv").string(), tag);
    write_text_atomically((s / "result.h5").string(), std::string(20000, 'x') + tag);
    fs::create_directory(s / "series");
    for (const char* slice : {"CT00001.dcm", "CT00002.dcm"}) write_text_atomically((s / "series" / slice).string(), tag);
    if (with_extra) write_text_atomically((s / "surface.vtp").string(), tag);
    write_text_atomically((s / "summary.json").string(), tag);
    folder.commit();
  }

  /// With a manifest, every entry it lists holds the same run's tag, returned; "" without one.
  std::string complete_run() const {
    if (!fs::exists(dir_ / kManifestName)) return "";
    const nlohmann::json m = nlohmann::json::parse(text_of(dir_ / kManifestName));
    std::set<std::string> tags;
    for (const auto& entry : m["runs"]["simulate"]) {
      const fs::path p = dir_ / entry.get<std::string>();
      if (fs::is_directory(p)) {
        for (const auto& f : fs::directory_iterator(p)) tags.insert(text_of(f.path()));
      } else {
        const std::string t = text_of(p);
        tags.insert(t.substr(t.find_first_not_of('x')));
      }
    }
    EXPECT_EQ(tags.size(), 1u) << "a complete folder mixes runs";
    return tags.empty() ? "?" : *tags.begin();
  }

  fs::path root_, dir_;
};

TEST_F(RunFolderTest, CommitMovesEverythingInAndWritesTheManifestLast) {
  run("run1", /*with_extra=*/true);
  EXPECT_EQ(complete_run(), "run1");
  EXPECT_TRUE(fs::exists(dir_ / "surface.vtp"));
  run("run2");
  EXPECT_EQ(complete_run(), "run2");
  EXPECT_FALSE(fs::exists(dir_ / "surface.vtp")) << "the earlier run's file this run did not write stays";
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir_)) names.insert(e.path().filename());
  EXPECT_EQ(names, (std::set<std::string>{kManifestName, "metrics.csv", "result.h5", "series", "summary.json"}));
}

TEST_F(RunFolderTest, AFailedRunLeavesTheEarlierRunWhole) {
  run("run1");
  {
    RunFolder folder(dir_.string(), "simulate", {"summary.json"});
    write_text_atomically(folder.staging() + "/metrics.csv", "run2");
  }  // no commit: the run failed
  EXPECT_EQ(complete_run(), "run1");
  for (const auto& e : fs::directory_iterator(dir_))
    EXPECT_EQ(e.path().filename().string().rfind(".staging-", 0), std::string::npos) << e.path();
}

TEST_F(RunFolderTest, AFailedFirstRunLeavesNoFolder) {
  { RunFolder folder((dir_ / "a" / "b").string(), "simulate", {}); }
  EXPECT_FALSE(fs::exists(dir_));
}

TEST_F(RunFolderTest, ASecondWriterIsRefused) {
  RunFolder first(dir_.string(), "simulate", {});
  try {
    RunFolder second(dir_.string(), "simulate", {});
    ADD_FAILURE() << "two writers in one folder";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("another VoxBreast run is writing to this output folder"), std::string::npos)
        << e.what();
  }
}

TEST_F(RunFolderTest, FilesVoxBreastDidNotWriteAreNeverReplaced) {
  fs::create_directories(dir_);
  write(dir_ / "summary.json", "mine");
  try {
    RunFolder folder(dir_.string(), "simulate", {"summary.json"});
    ADD_FAILURE() << "a foreign summary.json was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("holds 'summary.json', which no earlier VoxBreast run recorded writing"),
              std::string::npos)
        << e.what();
  }
  fs::remove(dir_ / "summary.json");
  write(dir_ / "surface.vtp", "mine");  // not always written: found at the commit, before anything moves
  write(dir_ / "notes.txt", "mine");    // never written by a run: kept through every run
  EXPECT_THROW(run("run1", /*with_extra=*/true), Error);
  EXPECT_EQ(text_of(dir_ / "surface.vtp"), "mine");
  EXPECT_FALSE(fs::exists(dir_ / "summary.json"));
  run("run1");
  run("run2");
  EXPECT_EQ(complete_run(), "run2");
  EXPECT_EQ(text_of(dir_ / "notes.txt"), "mine");
  EXPECT_EQ(text_of(dir_ / "surface.vtp"), "mine");
}

TEST_F(RunFolderTest, OtherCommandsKeepTheirFiles) {
  {
    RunFolder folder(dir_.string(), "phantom", {});
    write_text_atomically(folder.staging() + "/ct.nii.gz", "ct");
    folder.commit();
  }
  run("run1", true);
  run("run2");  // removes run1's surface.vtp, not the phantom's CT
  EXPECT_EQ(text_of(dir_ / "ct.nii.gz"), "ct");
  {
    RunFolder folder(dir_.string(), "phantom", {"ct.nii.gz"});  // the phantom may replace its own CT
    write_text_atomically(folder.staging() + "/ct.nii.gz", "ct2");
    folder.commit();
  }
  EXPECT_EQ(text_of(dir_ / "ct.nii.gz"), "ct2");
  EXPECT_EQ(complete_run(), "run2");
}

/// Runs killed (SIGKILL) at random points, then run again: whenever the folder has a manifest
/// it holds one complete run, a foreign file survives, and the next run cleans up what was left.
TEST_F(RunFolderTest, KillsAtRandomPointsNeverLeaveAMixedFolder) {
  fs::create_directories(dir_);
  write(dir_ / "notes.txt", "mine");
  std::mt19937 random(12345);
  int killed = 0, finished = 0;
  for (int i = 0; i < 60; ++i) {
    const std::string tag = "run" + std::to_string(i);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      try {
        run(tag);
      } catch (...) {
        ::_exit(2);
      }
      ::_exit(0);
    }
    std::this_thread::sleep_for(std::chrono::microseconds(std::uniform_int_distribution<int>(0, 3000)(random)));
    ::kill(child, SIGKILL);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    if (WIFSIGNALED(status)) ++killed;
    else {
      ASSERT_EQ(WEXITSTATUS(status), 0) << "run " << i << " failed";
      ++finished;
      EXPECT_EQ(complete_run(), tag);
    }
    const std::string seen = complete_run();  // "" (incomplete, said so) or one whole run
    EXPECT_TRUE(seen.empty() || seen.rfind("run", 0) == 0) << seen;
    EXPECT_EQ(text_of(dir_ / "notes.txt"), "mine");
  }
  EXPECT_GT(killed, 0);
  run("last");
  EXPECT_EQ(complete_run(), "last");
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir_)) names.insert(e.path().filename());
  EXPECT_EQ(names, (std::set<std::string>{kManifestName, "metrics.csv", "notes.txt", "result.h5", "series",
                                          "summary.json"}))
      << "leftovers of killed runs remain";
  std::printf("%d runs killed, %d finished\n", killed, finished);
}

}  // namespace
}  // namespace vb
