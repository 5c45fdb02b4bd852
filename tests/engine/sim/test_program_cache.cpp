// The on-disk program cache: entries read back whole or not at all, racing writers leave a whole
// entry, and a program loaded from the cache steps exactly as one built from source.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "engine/sim/opencl_runtime.hpp"
#include "engine/sim/program_cache.hpp"
#include "engine/sim/simulator.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

namespace fs = std::filesystem;

/// A fresh, empty folder under the system's temporary folder, removed with its contents.
struct TempFolder {
  fs::path path;
  TempFolder() {
    std::random_device seed;
    path = fs::temp_directory_path() / ("voxbreast-cache-test-" + std::to_string(::getpid()) + "-" +
                                        std::to_string(std::uniform_int_distribution<unsigned>()(seed)));
    fs::create_directories(path);
  }
  ~TempFolder() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

std::vector<fs::path> entries(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& f : fs::directory_iterator(dir)) out.push_back(f.path());
  return out;
}

/// The key an entry file holds (its third line onwards, as long as its header says).
std::string stored_key(const fs::path& entry) {
  std::ifstream in(entry, std::ios::binary);
  std::string magic, header;
  std::getline(in, magic);
  std::getline(in, header);
  std::string key(std::stoull(header), '\0');
  in.read(key.data(), std::streamsize(key.size()));
  return key;
}

std::vector<unsigned char> bytes(std::size_t n, unsigned seed) {
  std::vector<unsigned char> b(n);
  std::mt19937 gen(seed);
  for (auto& x : b) x = static_cast<unsigned char>(gen());
  return b;
}

TEST(ProgramCache, FolderComesFromTheOverrideThenXdgThenHome) {
  EXPECT_EQ(default_program_cache_dir("/tmp/vb", "/x", "/h"), fs::path("/tmp/vb"));
  EXPECT_EQ(default_program_cache_dir("", "/x", "/h"), fs::path("/x/voxbreast"));
  EXPECT_EQ(default_program_cache_dir(nullptr, nullptr, "/h"), fs::path("/h/.cache/voxbreast"));
  EXPECT_TRUE(default_program_cache_dir("off", "/x", "/h").empty());
  EXPECT_TRUE(default_program_cache_dir(nullptr, "", nullptr).empty());
}

TEST(ProgramCache, ReadsBackWhatWasWrittenAndOnlyForTheSameKey) {
  const TempFolder dir;
  const auto binary = bytes(10000, 1);
  EXPECT_FALSE(read_program_cache(dir.path, "key"));
  ASSERT_TRUE(write_program_cache(dir.path, "key", binary));
  const auto back = read_program_cache(dir.path, "key");
  ASSERT_TRUE(back);
  EXPECT_EQ(*back, binary);
  EXPECT_FALSE(read_program_cache(dir.path, "key2"));
  EXPECT_EQ(entries(dir.path).size(), 1u) << "no temporary file is left behind";
  const ProgramCacheUsage usage = program_cache_usage(dir.path);
  EXPECT_EQ(usage.entries, 1u);
  EXPECT_GT(usage.bytes, binary.size());
}

TEST(ProgramCache, CorruptOrTruncatedEntriesReadAsMissing) {
  const TempFolder dir;
  const auto binary = bytes(5000, 2);
  ASSERT_TRUE(write_program_cache(dir.path, "key", binary));
  const fs::path entry = entries(dir.path).at(0);
  const std::uintmax_t size = fs::file_size(entry);
  {  // one flipped byte in the binary
    std::fstream f(entry, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(std::streamoff(size - 100));
    f.put('\x5a' ^ static_cast<char>(binary[binary.size() - 100]));
  }
  EXPECT_FALSE(read_program_cache(dir.path, "key"));
  ASSERT_TRUE(write_program_cache(dir.path, "key", binary));
  ASSERT_TRUE(read_program_cache(dir.path, "key"));
  fs::resize_file(entry, size - 1);  // truncated, as by a full disk
  EXPECT_FALSE(read_program_cache(dir.path, "key"));
  fs::resize_file(entry, size + 1);  // one byte too many
  EXPECT_FALSE(read_program_cache(dir.path, "key"));
  std::ofstream(entry, std::ios::trunc) << "not an entry";
  EXPECT_FALSE(read_program_cache(dir.path, "key"));
}

TEST(ProgramCache, ClearRemovesEntriesAndNothingElse) {
  const TempFolder dir;
  ASSERT_TRUE(write_program_cache(dir.path, "a", bytes(100, 3)));
  ASSERT_TRUE(write_program_cache(dir.path, "b", bytes(100, 4)));
  std::ofstream(dir.path / "notes.txt") << "mine";
  EXPECT_EQ(program_cache_usage(dir.path).entries, 2u);
  EXPECT_EQ(clear_program_cache(dir.path), 2u);
  EXPECT_EQ(program_cache_usage(dir.path).entries, 0u);
  EXPECT_TRUE(fs::exists(dir.path / "notes.txt"));
}

TEST(ProgramCache, UnwritableFolderIsNotAnError) {
  const TempFolder dir;
  std::ofstream(dir.path / "file") << "x";
  EXPECT_FALSE(write_program_cache(dir.path / "file" / "sub", "key", bytes(10, 5)));
}

// Processes writing the same entry at once (MPI ranks, parallel tests) each succeed, and what
// stays is one whole entry.
TEST(ProgramCache, ConcurrentWritersLeaveOneWholeEntry) {
  const TempFolder dir;
  const auto binary = bytes(1 << 20, 6);
  constexpr int kWriters = 4, kRounds = 20;
  std::vector<pid_t> children;
  for (int w = 0; w < kWriters; ++w) {
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      bool ok = true;
      for (int r = 0; r < kRounds; ++r) {
        ok = write_program_cache(dir.path, "shared key", binary) && ok;
        const auto back = read_program_cache(dir.path, "shared key");
        ok = back && *back == binary && ok;  // a reader never sees a partial entry
      }
      _exit(ok ? 0 : 1);
    }
    children.push_back(pid);
  }
  for (const pid_t pid : children) {
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "a writer failed or read a partial entry";
  }
  EXPECT_EQ(entries(dir.path).size(), 1u) << "no temporary file is left behind";
  const auto back = read_program_cache(dir.path, "shared key");
  ASSERT_TRUE(back);
  EXPECT_EQ(*back, binary);
}

/// u and v after `steps` of a small block under gravity, on a fresh context (so none of this
/// process's programs are reused), with programs kept in `cache` (empty: built from source).
std::vector<double> trajectory(const fs::path& cache, int steps) {
  struct Restore {
    fs::path before = program_cache_dir();
    ~Restore() { set_program_cache_dir(before); }
  } restore;
  set_program_cache_dir(cache);
  const ClContext cl(test::cl_context().info);
  Scene s = test::mixed_block(Integrator::Heun, false);
  const test::Model m = test::make_model(s);
  Simulator sim(s, m.lattice, m.elements, cl);
  sim.advance(steps);
  return test::state_uv(sim);
}

// A program loaded from the cache is the one built from source: the same trajectory to the bit.
// A damaged entry, or one the driver refuses, is rebuilt from source and replaced.
TEST(ProgramCache, CachedProgramStepsExactlyAsTheBuiltOne) {
  const TempFolder dir;
  const std::vector<double> built = trajectory({}, 50);
  const std::vector<double> filled = trajectory(dir.path, 50);
  EXPECT_EQ(test::differing_values(built, filled), 0u);
  const auto cached = entries(dir.path);
  ASSERT_FALSE(cached.empty()) << "the first run stores its programs";
  std::vector<fs::file_time_type> written;
  for (const auto& f : cached) written.push_back(fs::last_write_time(f));

  const std::vector<double> loaded = trajectory(dir.path, 50);
  EXPECT_EQ(test::differing_values(built, loaded), 0u) << "a cache hit steps to the same bits";
  for (std::size_t i = 0; i < cached.size(); ++i)
    EXPECT_EQ(fs::last_write_time(cached[i]), written[i]) << "a hit does not rewrite " << cached[i];

  // every entry damaged, first truncated, then whole but with a binary the driver refuses: each
  // time the run builds from source, steps to the same bits and stores a whole entry again
  const auto garbage = bytes(4096, 7);
  for (const bool truncate : {true, false}) {
    for (const auto& f : cached) {
      if (truncate) fs::resize_file(f, fs::file_size(f) / 2);
      else ASSERT_TRUE(write_program_cache(dir.path, stored_key(f), garbage));
    }
    EXPECT_EQ(test::differing_values(built, trajectory(dir.path, 50)), 0u) << (truncate ? "truncated" : "refused");
    for (const auto& f : cached) {
      const auto entry = read_program_cache(dir.path, stored_key(f));
      ASSERT_TRUE(entry) << f << " is whole again";
      EXPECT_NE(*entry, garbage) << f << " holds the rebuilt binary";
    }
  }
  EXPECT_EQ(test::differing_values(built, trajectory(dir.path, 50)), 0u);
}

}  // namespace
}  // namespace vb
