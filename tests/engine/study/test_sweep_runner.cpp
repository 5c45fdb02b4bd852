// The sweep's bookkeeping without OpenCL: a stand-in case runner writes a summary.json computed
// from the case's values, so resume, ranks, workers and tables can be checked exactly and fast.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <set>
#include <string>
#include <thread>

#include "engine/error.hpp"
#include "engine/study/mpi_world.hpp"
#include "engine/study/sweep.hpp"
#include "engine/study/sweep_folder.hpp"
#include "engine/study/sweep_runner.hpp"
#include "engine/study/sweep_tables.hpp"
#include "io/atomic_file.hpp"

namespace vb {
namespace {

namespace fs = std::filesystem;

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

class SweepRunnerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("vb_sweep_test_" + std::to_string(::getpid()) + "_" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  /// x = 1..4 (x = 3 fails, like an unstable case) × y = a, b
  SweepGrid grid() const { return SweepGrid({parse_vary("p.x=1:4:4"), parse_vary("p.y=a,b")}); }

  std::vector<std::string> scenes(const SweepGrid& g) const {
    std::vector<std::string> texts;
    for (std::size_t i = 0; i < g.size(); ++i)
      texts.push_back(apply_scene_overrides("[p]\nx = 0\ny = 'z'\n", "test.toml", g.overrides_of(i)));
    return texts;
  }

  /// Stand-in for a simulation: summary.json from the values; x = 3 fails.
  SweepCaseRunner runner(std::vector<std::size_t>* ran = nullptr) {
    return [this, ran](const SweepCase& c, std::size_t worker) {
      {
        std::lock_guard lock(mutex_);
        if (ran) ran->push_back(c.index);
        workers_seen_.insert(worker);
      }
      const int x = int(c.index / 2) + 1;
      const std::string y = c.index % 2 ? "b" : "a";
      if (x == 3) throw Error("unstable at step 7", "case " + c.id, "use a smaller dt");
      const nlohmann::json summary = {{"displacement_m", 0.001 * x},
                                      {"converged", x != 2},
                                      {"steps", 100 * x},
                                      {"wall_time_s", 0.5 + double(c.index)},  // differs from run to run
                                      {"steps_per_second", 1e4 / (1 + c.index)},
                                      {"device", {{"name", "fake"}}},
                                      {"tracked", {{"apex", {{"displacement_m", {0.0, -0.5 * x, y == "a" ? 1 : 2}}}}}}};
      write_text_atomically(c.work_dir + "/summary.json", summary.dump(2));
      EXPECT_NE(read_file(c.work_dir + "/scene.toml").find("x = " + std::to_string(x)), std::string::npos);
    };
  }

  /// Runs (a share of) the sweep into `dir`, then rebuilds the tables; returns metrics.csv.
  std::string sweep(const std::string& dir, SweepRunOptions options = {}, std::vector<std::size_t>* ran = nullptr) {
    const SweepGrid g = grid();
    const SweepFolder folder(dir, g.size());
    folder.open(sweep_definition(g, "test.toml", "[p]\nx = 0\n", "minimal"));
    run_sweep_cases(folder, g, scenes(g), runner(ran), options);
    write_sweep_tables(folder, g);
    return read_file(folder.path("metrics.csv"));
  }

  fs::path root_;
  std::mutex mutex_;
  std::set<std::size_t> workers_seen_;
};

TEST_F(SweepRunnerTest, MetricsTableHasOneRowPerCaseWithStatusAndFlattenedSummary) {
  const std::string metrics = sweep(root_ / "serial");
  const std::string header = metrics.substr(0, metrics.find('\n'));
  EXPECT_EQ(header,
            "case,p.x,p.y,status,error,converged,displacement_m,steps,"
            "tracked.apex.displacement_m.1,tracked.apex.displacement_m.2,tracked.apex.displacement_m.3");
  EXPECT_NE(metrics.find("\n0001,1,a,ok,,true,0.001,100,0,-0.5,1\n"), std::string::npos) << metrics;
  EXPECT_NE(metrics.find("\n0004,2,b,ok,,false,0.002,200,0,-1,2\n"), std::string::npos) << metrics;
  EXPECT_NE(metrics.find("\n0005,3,a,failed,case 0005: unstable at step 7 (use a smaller dt),,,,,,\n"), std::string::npos)
      << metrics;
  const std::string timing = read_file(root_ / "serial" / "timing.csv");
  EXPECT_EQ(timing.substr(0, timing.find('\n')), "case,status,rank,worker,device,case_wall_time_s,steps_per_second,wall_time_s");
  EXPECT_TRUE(fs::is_regular_file(root_ / "serial" / "cases" / "0008" / "case.json"));
  EXPECT_TRUE(fs::is_regular_file(root_ / "serial" / "sweep_log.jsonl"));
}

TEST_F(SweepRunnerTest, StoppedAndRestartedSweepGivesTheSameMetricsAndRunsEachCaseOnce) {
  const std::string uninterrupted = sweep(root_ / "serial");
  SweepRunOptions first;
  first.stop_after = 3;
  std::vector<std::size_t> ran;
  const std::string partial = sweep(root_ / "resumed", first, &ran);
  EXPECT_EQ(ran.size(), 3u);
  EXPECT_NE(partial.find(",pending,"), std::string::npos);
  // A killed run leaves a half-written working folder behind: it must not count as finished.
  fs::create_directories(root_ / "resumed" / "cases" / ".0004.work-r0-p1");
  fs::create_directories(root_ / "resumed" / "cases" / ".0004.notes");  // someone else's
  write_text_atomically((root_ / "resumed" / "cases" / ".0004.work-r0-p1" / "summary.json").string(), "{\"steps\": ");
  const std::string resumed = sweep(root_ / "resumed", {}, &ran);
  EXPECT_EQ(ran.size(), 8u);
  EXPECT_EQ(std::set<std::size_t>(ran.begin(), ran.end()).size(), 8u) << "a finished case ran again";
  EXPECT_EQ(resumed, uninterrupted);
  EXPECT_FALSE(fs::exists(root_ / "resumed" / "cases" / ".0004.work-r0-p1"));
  EXPECT_TRUE(fs::exists(root_ / "resumed" / "cases" / ".0004.notes")) << "a folder the sweep did not make was removed";
}

TEST_F(SweepRunnerTest, RanksTakeEveryNthCaseAndTogetherMatchOneProcess) {
  const std::string serial = sweep(root_ / "serial");
  std::vector<std::size_t> ran0, ran1;
  SweepRunOptions rank0, rank1;
  rank0.ranks = rank1.ranks = 2;
  rank1.rank = 1;
  // Leftovers of a killed run: each rank removes only those of its own cases.
  const fs::path cases = root_ / "ranks" / "cases";
  fs::create_directories(cases / ".0002.work-r1-p7");  // case index 1: rank 1's
  fs::create_directories(cases / ".0003.work-r0-p7");  // case index 2: rank 0's
  sweep(root_ / "ranks", rank0, &ran0);
  EXPECT_TRUE(fs::exists(cases / ".0002.work-r1-p7")) << "rank 0 removed a folder rank 1 may be writing";
  EXPECT_FALSE(fs::exists(cases / ".0003.work-r0-p7"));
  EXPECT_EQ(ran0, (std::vector<std::size_t>{0, 2, 4, 6}));
  const std::string both = sweep(root_ / "ranks", rank1, &ran1);
  EXPECT_EQ(ran1, (std::vector<std::size_t>{1, 3, 5, 7}));
  EXPECT_FALSE(fs::exists(cases / ".0002.work-r1-p7"));
  EXPECT_EQ(both, serial);
}

TEST_F(SweepRunnerTest, WorkerThreadsShareTheCasesAndMatchOneWorker) {
  const std::string serial = sweep(root_ / "serial");
  SweepRunOptions threads;
  threads.workers = {"dev0", "dev1", "dev2"};
  std::vector<std::size_t> ran;
  EXPECT_EQ(sweep(root_ / "threads", threads, &ran), serial);
  EXPECT_EQ(ran.size(), 8u);
  EXPECT_GE(workers_seen_.size(), 1u);
  const std::string timing = read_file(root_ / "threads" / "timing.csv");
  EXPECT_NE(timing.find(",dev"), std::string::npos);
}

TEST_F(SweepRunnerTest, RetryFailedRunsOnlyTheFailedCases) {
  sweep(root_ / "retry");
  std::vector<std::size_t> ran;
  SweepRunOptions again;
  sweep(root_ / "retry", again, &ran);
  EXPECT_TRUE(ran.empty());
  again.retry_failed = true;
  sweep(root_ / "retry", again, &ran);
  EXPECT_EQ(ran, (std::vector<std::size_t>{4, 5}));
}

TEST_F(SweepRunnerTest, AnotherGridInTheSameFolderIsAnError) {
  const SweepGrid g = grid();
  const SweepFolder folder((root_ / "grid").string(), g.size());
  folder.open(sweep_definition(g, "test.toml", "[p]\nx = 0\n", "minimal"));
  EXPECT_NO_THROW(folder.open(sweep_definition(g, "test.toml", "[p]\nx = 0\n", "minimal")));
  const SweepGrid other({parse_vary("p.x=1:4:4"), parse_vary("p.y=a,c")});
  try {
    folder.open(sweep_definition(other, "test.toml", "[p]\nx = 0\n", "minimal"));
    FAIL() << "a different grid must be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--vary p.y had the values"), std::string::npos) << e.what();
  }
  EXPECT_THROW(folder.open(sweep_definition(g, "test.toml", "[p]\nx = 1\n", "minimal")), Error);
  EXPECT_THROW(folder.open(sweep_definition(g, "test.toml", "[p]\nx = 0\n", "full")), Error);
}

/// The scene text of a resumed sweep can stay the same while the CT it names changes: the sweep
/// records a SHA-256 of every input file and refuses to resume over changed data.
TEST_F(SweepRunnerTest, ResumeIsRefusedWhenAnInputFileChanged) {
  const fs::path sample = fs::path(VOXBREAST_SOURCE_DIR) / "data-samples" / "phantom";
  const fs::path data = root_ / "data";
  fs::create_directories(data);
  for (const char* file : {"scene.toml", "ct.nii.gz", "labels.nii.gz"}) fs::copy_file(sample / file, data / file);
  const SweepPlan plan = plan_sweep((data / "scene.toml").string(), {parse_vary("materials.skin.E=40000,50000")});
  EXPECT_EQ(plan.input_files, (std::vector<std::string>{(data / "ct.nii.gz").string(), (data / "labels.nii.gz").string()}));
  const MpiWorld world;
  SweepOptions options;
  options.out_dir = (root_ / "sweep").string();
  options.stop_after = 1;  // killed after one case
  const SweepCaseRunner run_case = [](const SweepCase& c, std::size_t) {
    write_text_atomically(c.work_dir + "/summary.json", "{\"steps\": 1}");
  };
  run_sweep(plan, options, world, run_case);
  run_sweep(plan, options, world, run_case);  // resumes: nothing changed
  fs::copy_file(data / "labels.nii.gz", data / "ct.nii.gz", fs::copy_options::overwrite_existing);
  try {
    run_sweep(plan, options, world, run_case);
    ADD_FAILURE() << "resumed over a changed CT";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("the input file " + (data / "ct.nii.gz").string() + " has changed"),
              std::string::npos)
        << e.what();
  }
}

/// A new sweep refused a folder whose metrics.csv or cases/ it would replace or mix with.
TEST_F(SweepRunnerTest, ANewSweepNeverReplacesFilesItDidNotWrite) {
  const SweepGrid g = grid();
  for (const char* name : {"metrics.csv", "timing.csv", "cases/0001"}) {
    const fs::path dir = root_ / ("foreign_" + std::to_string(name[0] == 'c' ? 2 : name[0] == 'm' ? 0 : 1));
    fs::create_directories((dir / name).parent_path());
    write_text_atomically((dir / name).string(), "mine");
    const SweepFolder folder(dir.string(), g.size());
    try {
      folder.open(sweep_definition(g, "test.toml", "[p]\nx = 0\n", "minimal"));
      ADD_FAILURE() << "a folder holding " << name << " was taken";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("which is not a VoxBreast sweep's"), std::string::npos) << e.what();
    }
    EXPECT_EQ(read_file(dir / name), "mine");
    EXPECT_FALSE(fs::exists(dir / "sweep.json"));
  }
}

TEST_F(SweepRunnerTest, OneSweepAtATimePerFolder) {
  const SweepFolder folder(root_.string(), 1);
  const SweepFolder::Lock held = folder.lock();
  EXPECT_THROW(folder.lock(), Error);
}

TEST_F(SweepRunnerTest, CaseIdsHaveOneWidth) {
  EXPECT_EQ(SweepFolder("d", 12).case_id(0), "0001");
  EXPECT_EQ(SweepFolder("d", 12345).case_id(41), "00042");
}

TEST(SweepTables, FlattensScalarsWithOneBasedIndicesAndLeavesStringsOut) {
  const nlohmann::json doc = {{"a", 1}, {"b", {{"c", {1.5, 2.5}}, {"name", "x"}}}, {"d", nullptr}, {"e", true}};
  const auto flat = flatten_scalars(doc);
  ASSERT_EQ(flat.size(), 5u);
  EXPECT_EQ(flat[0].first, "a");
  EXPECT_EQ(flat[1].first, "b.c.1");
  EXPECT_EQ(flat[2].first, "b.c.2");
  EXPECT_EQ(flat[3].first, "d");
  EXPECT_EQ(scalar_text(flat[3].second), "");
  EXPECT_EQ(scalar_text(flat[4].second), "true");
  EXPECT_EQ(scalar_text(nlohmann::json(0.1)), "0.1");
  EXPECT_EQ(scalar_text(nlohmann::json(-3)), "-3");
  EXPECT_TRUE(is_timing_field("wall_time_s"));
  EXPECT_TRUE(is_timing_field("equilibrium.wall_time_s"));
  EXPECT_TRUE(is_timing_field("steps_per_second"));
  EXPECT_FALSE(is_timing_field("simulated_time_s"));
  EXPECT_FALSE(is_timing_field("tracked.wall.displacement_m.1"));
  // a simulation's phase times and its image outputs' seconds and memory vary from run to run
  EXPECT_TRUE(is_timing_field("timings.solve_s"));
  EXPECT_TRUE(is_timing_field("image_outputs.step_seconds.dvf_inverse"));
  EXPECT_TRUE(is_timing_field("image_outputs.host_memory.peak_bytes"));
  EXPECT_FALSE(is_timing_field("image_outputs.model_labels.file"));
}

}  // namespace
}  // namespace vb
