// What `voxbreast view` serves of a folder (apps/view_folder.hpp): the kind of each output folder,
// the files the page may read, and the paths refused because they leave the folder.
#include "apps/view_folder.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "engine/error.hpp"

namespace fs = std::filesystem;
using vb::app::resolve_inside;
using vb::app::scan_view_folder;

namespace {

/// A fresh folder under the system's temporary folder, removed with the fixture.
class ViewFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::mt19937_64 rng(std::hash<std::string>{}(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    dir_ = fs::temp_directory_path() / ("voxbreast-view-test-" + std::to_string(rng()));
    fs::create_directories(dir_);
    dir_ = fs::canonical(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void touch(const std::string& relative, const std::string& text = "x") {
    fs::create_directories((dir_ / relative).parent_path());
    std::ofstream(dir_ / relative) << text;
  }
  fs::path dir_;
};

struct KindCase {
  const char* kind;
  std::vector<const char*> files;
};

}  // namespace

TEST_F(ViewFolderTest, KindOfEachOutputFolder) {
  const KindCase cases[] = {
      {"simulate", {"summary.json", "result.h5", "metrics.csv"}},
      {"simulate", {"summary.json", "surface.vtp"}},
      {"sweep", {"metrics.csv", "timing.csv", "cases/0001/summary.json"}},
      {"fit", {"summary.json", "regions.csv", "history.csv"}},
      {"probe", {"probe_summary.json", "probe_curves.csv", "probe_profile.csv"}},
      {"bench", {"bench.json", "bench.csv"}},
      {"haptic", {"haptic.csv", "haptic_summary.json"}},
      {"fit_curve", {"fit_curve.json", "fit_curve.csv"}},
      {"phantom", {"ct.nii.gz", "labels.nii.gz", "scene.toml"}},
      {"unknown", {"notes.txt"}},
  };
  for (const KindCase& c : cases) {
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    for (const char* f : c.files) touch(f);
    EXPECT_EQ(scan_view_folder(dir_).kind, c.kind) << "files: " << c.files.front() << ", ...";
  }
}

TEST_F(ViewFolderTest, ListsOnlyTheFilesThePageReads) {
  for (const char* f : {"summary.json", "result.h5", "surface.vtp", "surface.stl", "lattice.vtu", "dvf.nii.gz",
                        "dvf_inverse.nii.gz", "warped_ct.nii.gz", "frames/surface_0001.vtp", "frames/lattice_0001.vtu",
                        "warped_ct_dicom/CT00001.dcm", ".voxbreast-manifest.json", ".staging-1/summary.json",
                        "plots/max_displacement_m.png"})
    touch(f);
  const auto folder = scan_view_folder(dir_);
  const std::vector<std::string> expected = {"frames/surface_0001.vtp", "plots/max_displacement_m.png", "summary.json",
                                             "surface.vtp", "warped_ct.nii.gz"};
  EXPECT_EQ(folder.files, expected);
  const auto manifest = vb::app::view_manifest(folder);
  EXPECT_EQ(manifest["kind"], "simulate");
  EXPECT_EQ(manifest["files"][0], "data/frames/surface_0001.vtp");
  EXPECT_TRUE(manifest["input_ct"].is_null());
}

TEST_F(ViewFolderTest, SkipsLinksOutOfTheFolder) {
  touch("summary.json");
  touch("surface.vtp");
  fs::create_symlink("/etc/passwd", dir_ / "leak.json");
  fs::create_symlink(dir_ / "summary.json", dir_ / "alias.json");
  const auto files = scan_view_folder(dir_).files;
  EXPECT_EQ(std::count(files.begin(), files.end(), "leak.json"), 0);
  EXPECT_EQ(std::count(files.begin(), files.end(), "alias.json"), 1);
}

TEST_F(ViewFolderTest, ResolveInsideRefusesEveryWayOut) {
  touch("summary.json");
  touch("frames/surface_0001.vtp");
  fs::create_symlink("/etc/passwd", dir_ / "leak.json");
  EXPECT_EQ(resolve_inside(dir_, "summary.json"), dir_ / "summary.json");
  EXPECT_EQ(resolve_inside(dir_, "frames/surface_0001.vtp"), dir_ / "frames/surface_0001.vtp");
  for (const std::string& bad : std::vector<std::string>{"", "/etc/passwd", "../summary.json", "frames/../summary.json", "./summary.json",
                                "frames//surface_0001.vtp", "frames/", "..", "frames\\..\\summary.json",
                                std::string("summary.json\0x", 14), "leak.json", "missing.json", "frames"})
    EXPECT_FALSE(resolve_inside(dir_, bad)) << "'" << bad << "' was resolved";
}

TEST_F(ViewFolderTest, RefusesAMissingFolderAndAMissingCt) {
  EXPECT_THROW(scan_view_folder(dir_ / "missing"), vb::Error);
  touch("summary.json");
  EXPECT_THROW(scan_view_folder(dir_, dir_ / "missing_ct.nii.gz"), vb::Error);
}

TEST_F(ViewFolderTest, FindsTheInputCtThroughTheScene) {
  touch("input/ct.nii.gz");
  touch("input/scene.toml", "[model]\nimage = \"ct.nii.gz\"\n");
  touch("run/summary.json", "{\"scene\": \"" + (dir_ / "input/scene.toml").string() + "\"}");
  touch("run/result.h5");
  touch("run/warped_ct.nii.gz");
  const auto folder = scan_view_folder(dir_ / "run");
  EXPECT_EQ(folder.input_ct, dir_ / "input/ct.nii.gz");
  EXPECT_EQ(vb::app::view_manifest(folder)["input_ct"], "input/ct.nii.gz");
  fs::remove(dir_ / "input/ct.nii.gz");
  const auto without = scan_view_folder(dir_ / "run");
  EXPECT_TRUE(without.input_ct.empty());
  EXPECT_NE(without.input_ct_note.find("--ct"), std::string::npos) << without.input_ct_note;
}
