// Every writer on a full disk: a one-line vb::Error naming the file and "no space left on device",
// no temporary file left, and (result.h5) no crash when the process exits afterwards. The disk is
// a 64 KiB tmpfs, which needs root (CI runs as root); elsewhere the tests are skipped.
#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <functional>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>

#include "engine/error.hpp"
#include "engine/lattice/lattice.hpp"
#include "io/atomic_file.hpp"
#include "io/dicom_io.hpp"
#include "io/hdf5_result.hpp"
#include "io/nifti_io.hpp"

namespace fs = std::filesystem;

namespace vb {
namespace {

class FullDisk : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("voxbreast-full-disk-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    if (::mount("tmpfs", dir_.c_str(), "tmpfs", 0, "size=64k") != 0) {
      fs::remove(dir_);
      GTEST_SKIP() << "cannot mount a 64 KiB tmpfs (needs root): " << std::strerror(errno);
    }
    mounted_ = true;
  }
  void TearDown() override {
    if (mounted_) ::umount(dir_.c_str());
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  /// The error must be one line, name `file` and say that the disk is full; nothing is left.
  void expect_full_disk_error(const std::string& message, const fs::path& file) const {
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find("no space left on device"), std::string::npos) << message;
    EXPECT_TRUE(fs::is_empty(dir_)) << "a temporary file or folder was left behind";
  }

  static std::string error_of(const std::function<void()>& body) {
    try {
      body();
    } catch (const Error& e) {
      return e.what();
    }
    ADD_FAILURE() << "no vb::Error";
    return {};
  }

  static ImageVolume image() {
    ImageVolume v;
    v.dims = {64, 64, 16};
    v.affine_lps_m.topLeftCorner<3, 3>() = 1e-3 * Eigen::Matrix3d::Identity();
    v.values.resize(v.voxel_count());
    // Random floats, so that the .nii.gz too stays far larger than the 64 KiB disk.
    std::mt19937 random(7);
    std::uniform_real_distribution<float> hu(-1000.0f, 1000.0f);
    for (float& value : v.values) value = hu(random);
    v.modality = "CT";
    return v;
  }

  fs::path dir_;
  bool mounted_ = false;
};

/// The result.h5 writer on a full disk, run in a fresh process by FullDisk.ResultH5 (so that HDF5
/// starts there, as in `voxbreast simulate`); skipped when run on its own.
TEST(FullDiskChild, WritesResultH5) {
  const char* dir = std::getenv("VB_FULL_DISK_DIR");
  if (!dir) GTEST_SKIP() << "run by FullDisk.ResultH5";
  const fs::path file = fs::path(dir) / "result.h5";
  LabelVolume volume;  // a 30 × 30 × 30 block: 27000 elements, far more than 64 KiB of state
  volume.dims = {30, 30, 30};
  volume.spacing_m = 0.002;
  volume.tissue_names = {"adipose"};
  volume.labels.assign(27000, 1);
  const Lattice lattice = build_lattice(volume);
  const std::size_t n = lattice.element_count();
  FinalState state;
  state.position_m.assign(3 * n, 0.01);
  state.displacement_m.assign(3 * n, 0.001);
  state.velocity_m_s.assign(3 * n, 0.0);
  state.volumetric_strain.assign(n, 0.0);
  state.equivalent_strain.assign(n, 0.0);
  state.von_mises_stress_pa.assign(n, 0.0);
  try {
    write_result_h5(file.string(), lattice, Scene{}, state, Frames{}, RunSummary{});
    ADD_FAILURE() << "no error on a full disk";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find("no space left on device"), std::string::npos) << message;
  }
  EXPECT_TRUE(fs::is_empty(dir)) << "the temporary file was left behind";
}

/// HDF5 left a dataset open after the failed close and crashed in its own shutdown at exit: the
/// writer runs in a child process, which must report the full disk and then exit normally.
TEST_F(FullDisk, ResultH5) {
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::setenv("VB_FULL_DISK_DIR", dir_.c_str(), 1);
    ::execl("/proc/self/exe", "test_io", "--gtest_filter=FullDiskChild.WritesResultH5", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "the process died of signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 0) << "FullDiskChild.WritesResultH5 failed (its output is above)";
}

TEST_F(FullDisk, Text) {
  const fs::path file = dir_ / "summary.json";
  const std::string message = error_of([&] { write_text_atomically(file.string(), std::string(200000, 'x')); });
  expect_full_disk_error(message, file);
}

TEST_F(FullDisk, Nifti) {
  for (const char* name : {"warped_ct.nii", "warped_ct.nii.gz"}) {
    const fs::path file = dir_ / name;
    const std::string message = error_of([&] { write_nifti(file.string(), image(), NiftiType::Float32); });
    expect_full_disk_error(message, file);
  }
}

TEST_F(FullDisk, DicomSeries) {
  const fs::path series = dir_ / "warped_ct_dicom";
  const std::string message = error_of([&] { write_dicom_series(series.string(), image(), "full disk"); });
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_NE(message.find(dir_.string()), std::string::npos) << message;
  EXPECT_NE(message.find("no space left on device"), std::string::npos) << message;
  EXPECT_TRUE(fs::is_empty(dir_)) << "a staging folder or slice was left behind";
}

}  // namespace
}  // namespace vb
