// DICOM series reading and writing, checked against independent readers: pydicom (Debian's
// python3-pydicom and its sample files) and DCMTK's command-line tools (dcmdump, dcmodify,
// dcmcjpeg, dcmcjpls, dcmcrle). Tests that need a missing tool or file skip with the reason.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "engine/error.hpp"
#include "engine/image/image_volume.hpp"
#include "io/dicom_io.hpp"

namespace fs = std::filesystem;

namespace vb {
namespace {

const fs::path kPydicomData = "/usr/lib/python3/dist-packages/pydicom/data/test_files";
const char* kPython = "/usr/bin/python3";

// ---- helpers: temporary folders, commands ----------------------------------------------------

class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = fs::temp_directory_path() /
            ("vb_dicom_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }
  fs::path operator/(const std::string& name) const { return path_ / name; }

 private:
  fs::path path_;
};

struct CommandResult {
  int exit_code = -1;
  std::string output;  ///< stdout
};

CommandResult run_command(const std::string& command) {
  CommandResult result;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), int(buffer.size()), pipe)) result.output += buffer.data();
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

bool have_tool(const std::string& name) { return fs::exists("/usr/bin/" + name); }

bool have_pydicom() {
  return fs::exists(kPython) &&
         run_command(std::string(kPython) + " -c 'import pydicom, numpy' 2>/dev/null").exit_code ==
             0;
}

/// Runs a Python snippet (no single quotes in it) with the arguments; its stdout as numbers/words.
std::vector<std::string> python_words(const std::string& script, const std::string& args) {
  const CommandResult result =
      run_command(std::string(kPython) + " -c '" + script + "' " + args + " 2>&1");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  std::istringstream in(result.output);
  std::vector<std::string> words;
  for (std::string word; in >> word;) words.push_back(word);
  return words;
}

std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir)) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

fs::path copy_folder(const fs::path& from, const fs::path& to) {
  fs::create_directories(to);
  for (const auto& file : files_in(from)) fs::copy_file(file, to / file.filename());
  return to;
}

/// Runs `body` expecting a vb::Error; returns its message ("" and a failure if none was thrown).
template <class Body>
std::string error_of(Body&& body) {
  try {
    body();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a vb::Error";
  return {};
}

// ---- the test volume -------------------------------------------------------------------------

/// An oblique (rotated about two axes), anisotropic, right-handed volume with fractional HU.
ImageVolume oblique_volume(int slices = 6) {
  ImageVolume v;
  v.dims = {12, 9, slices};
  const Eigen::Matrix3d rotation = (Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix();
  const Eigen::Vector3d spacing_m(0.7e-3, 0.9e-3, 2.5e-3);
  v.affine_lps_m.topLeftCorner<3, 3>() = rotation * spacing_m.asDiagonal();
  v.affine_lps_m.topRightCorner<3, 1>() = Eigen::Vector3d(-0.1234567, 0.0456789, 0.2101010);
  v.values.resize(v.voxel_count());
  for (int k = 0; k < v.dims[2]; ++k)
    for (int j = 0; j < v.dims[1]; ++j)
      for (int i = 0; i < v.dims[0]; ++i)
        v.values[v.linear_index(i, j, k)] = float(-1000 + 37 * i - 11 * j + 53 * k + 0.3 * (i % 3));
  v.modality = "CT";
  v.dicom_tags = {{"0010,0010", "Doe^Jane"},      {"0010,0020", "P123"},
                  {"0020,000D", "1.2.826.0.1.1"}, {"0020,0052", "1.2.826.0.1.2"},
                  {"0008,0020", "20240102"},      {"source_series_uid", "1.2.826.0.1.3"}};
  return v;
}

std::vector<float> rounded(const std::vector<float>& values) {
  std::vector<float> out(values.size());
  std::transform(values.begin(), values.end(), out.begin(), [](float v) { return std::round(v); });
  return out;
}

void expect_same_volume(const ImageVolume& a, const ImageVolume& b) {
  EXPECT_EQ(a.dims, b.dims);
  EXPECT_TRUE(a.affine_lps_m.isApprox(b.affine_lps_m, 1e-12)) << a.affine_lps_m << "\n\n"
                                                              << b.affine_lps_m;
  EXPECT_EQ(a.values, b.values);
}

/// A written series of the oblique volume, reused by most tests.
class DicomSeriesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    volume_ = oblique_volume();
    series_ = tmp_ / "series";
    write_dicom_series(series_.string(), volume_, "oblique test");
  }
  TempDir tmp_;
  ImageVolume volume_;
  fs::path series_;
};

// ---- an external sample: pydicom's CT_small.dcm ----------------------------------------------

TEST(DicomRead, CtSmallMatchesPydicom) {
  const fs::path sample = kPydicomData / "CT_small.dcm";
  if (!fs::exists(sample)) GTEST_SKIP() << "missing " << sample << " (python3-pydicom)";
  if (!have_pydicom()) GTEST_SKIP() << "pydicom/numpy not importable by " << kPython;
  TempDir tmp;
  fs::copy_file(sample, tmp / "CT_small.dcm");

  const ImageVolume v = read_dicom_series(tmp.path().string());
  // rows cols, PixelSpacing (2), IPP (3), IOP (6), SliceThickness, mean HU, 4 HU at (row, col).
  const std::vector<std::string> w = python_words(
      "import sys, pydicom, numpy\n"
      "d = pydicom.dcmread(sys.argv[1])\n"
      "hu = d.pixel_array.astype(numpy.float64) * float(d.RescaleSlope) + "
      "float(d.RescaleIntercept)\n"
      "print(d.Rows, d.Columns, *d.PixelSpacing, *d.ImagePositionPatient, "
      "*d.ImageOrientationPatient, d.SliceThickness, repr(hu.mean()), d.PatientID)\n"
      "print(*[repr(hu[r, c]) for r, c in [(0, 0), (32, 64), (127, 127), (100, 10)]])",
      quoted(tmp / "CT_small.dcm"));
  ASSERT_EQ(w.size(), 20u);
  auto num = [&](int n) { return std::stod(w[std::size_t(n)]); };

  const int rows = int(num(0)), columns = int(num(1));
  EXPECT_EQ(v.dims, (std::array<int, 3>{columns, rows, 1}));
  const Eigen::Vector3d row_dir(num(7), num(8), num(9)), col_dir(num(10), num(11), num(12));
  const Eigen::Vector3d ipp(num(4), num(5), num(6));
  Eigen::Matrix4d expected = Eigen::Matrix4d::Identity();
  expected.block<3, 1>(0, 0) = row_dir * num(3) * 1e-3;  // i: along a row, column spacing
  expected.block<3, 1>(0, 1) = col_dir * num(2) * 1e-3;  // j: down a column, row spacing
  expected.block<3, 1>(0, 2) = row_dir.cross(col_dir) * num(13) * 1e-3;
  expected.block<3, 1>(0, 3) = ipp * 1e-3;
  EXPECT_TRUE(v.affine_lps_m.isApprox(expected, 1e-9)) << v.affine_lps_m << "\n\n" << expected;

  double sum = 0;
  for (float value : v.values) sum += value;
  EXPECT_NEAR(sum / double(v.values.size()), num(14), 1e-6);
  const std::array<std::array<int, 2>, 4> row_col = {{{0, 0}, {32, 64}, {127, 127}, {100, 10}}};
  for (int n = 0; n < 4; ++n)
    EXPECT_EQ(v.values[v.linear_index(row_col[n][1], row_col[n][0], 0)], float(num(16 + n)))
        << "row " << row_col[n][0] << " column " << row_col[n][1];

  EXPECT_EQ(v.modality, "CT");
  EXPECT_EQ(v.dicom_tags.at("0010,0020"), w[15]);
  EXPECT_FALSE(v.dicom_tags.at("0020,000D").empty());
  EXPECT_FALSE(v.dicom_tags.at("source_series_uid").empty());
}

/// pydicom's MR sample stored uncompressed, RLE, JPEG-LS, implicit VR and big endian: all must
/// give equal volumes; its JPEG 2000 copy has no decoder in DCMTK and must be refused by name.
TEST(DicomRead, PydicomCompressedSamplesDecodeAlike) {
  const std::vector<std::string> names = {
      "MR_small.dcm",          "MR_small_RLE.dcm",       "MR_small_jpeg_ls_lossless.dcm",
      "MR_small_implicit.dcm", "MR_small_bigendian.dcm", "MR_small_jp2klossless.dcm"};
  const std::size_t readable = names.size() - 1;
  for (const auto& name : names)
    if (!fs::exists(kPydicomData / name)) GTEST_SKIP() << "missing " << kPydicomData / name;
  DicomReadOptions any;
  any.accept_any_modality = true;
  std::vector<ImageVolume> volumes;
  for (std::size_t n = 0; n < readable; ++n) {
    TempDir tmp;
    fs::copy_file(kPydicomData / names[n], tmp / names[n]);
    volumes.push_back(read_dicom_series(tmp.path().string(), any));
    EXPECT_EQ(volumes.back().modality, "MR");
    if (n > 0) {
      SCOPED_TRACE(names[n]);
      expect_same_volume(volumes[0], volumes[n]);
    }
  }

  TempDir tmp;
  fs::copy_file(kPydicomData / names[readable], tmp / names[readable]);
  const std::string message = error_of([&] { read_dicom_series(tmp.path().string(), any); });
  EXPECT_NE(message.find("JPEG 2000"), std::string::npos) << message;
  EXPECT_NE(message.find(names[readable]), std::string::npos) << message;
}

// ---- round trip through the writer -----------------------------------------------------------

TEST_F(DicomSeriesTest, RoundTripKeepsGeometryValuesAndStudy) {
  ASSERT_EQ(files_in(series_).size(), std::size_t(volume_.dims[2]));
  const ImageVolume back = read_dicom_series(series_.string());
  EXPECT_EQ(back.dims, volume_.dims);
  EXPECT_LT((back.affine_lps_m - volume_.affine_lps_m).cwiseAbs().maxCoeff(), 1e-6)
      << back.affine_lps_m << "\n\n"
      << volume_.affine_lps_m;
  EXPECT_EQ(back.values, rounded(volume_.values));
  EXPECT_EQ(back.modality, "CT");
  for (const char* key : {"0010,0010", "0010,0020", "0020,000D", "0020,0052", "0008,0020"})
    EXPECT_EQ(back.dicom_tags.at(key), volume_.dicom_tags.at(key)) << key;
  EXPECT_NE(back.dicom_tags.at("source_series_uid"), volume_.dicom_tags.at("source_series_uid"));

  const auto series = list_dicom_series(series_.string());
  ASSERT_EQ(series.size(), 1u);
  EXPECT_EQ(series[0].series_uid, back.dicom_tags.at("source_series_uid"));
  EXPECT_EQ(series[0].modality, "CT");
  EXPECT_EQ(series[0].description, "oblique test");
  EXPECT_EQ(series[0].files, volume_.dims[2]);
}

TEST_F(DicomSeriesTest, DcmdumpReadsEveryFile) {
  if (!have_tool("dcmdump")) GTEST_SKIP() << "dcmdump missing (Debian package dcmtk)";
  for (const auto& file : files_in(series_))
    EXPECT_EQ(run_command("dcmdump " + quoted(file) + " >/dev/null 2>&1").exit_code, 0) << file;
}

/// An independent reader sees new shared series UID, unique instance UIDs, the copied patient,
/// and each slice where the affine puts it (catches a row/column mix-up the reader could mirror).
TEST_F(DicomSeriesTest, PydicomSeesUidsPatientAndPositions) {
  if (!have_pydicom()) GTEST_SKIP() << "pydicom/numpy not importable by " << kPython;
  const std::vector<std::string> w = python_words(
      "import sys, glob, pydicom\n"
      "for f in sorted(glob.glob(sys.argv[1] + \"/*\")):\n"
      "  d = pydicom.dcmread(f)\n"
      "  print(d.SeriesInstanceUID, d.SOPInstanceUID, d.PatientID, d.InstanceNumber, "
      "*d.ImagePositionPatient, *d.ImageOrientationPatient[:3], *d.PixelSpacing, "
      "repr(float(d.pixel_array[1, 2]) * float(d.RescaleSlope) + float(d.RescaleIntercept)))",
      quoted(series_));
  constexpr std::size_t per_file = 13;
  ASSERT_EQ(w.size(), per_file * std::size_t(volume_.dims[2]));
  std::set<std::string> series_uids, instance_uids;
  const Eigen::Vector3d row_direction = volume_.affine_lps_m.block<3, 1>(0, 0).normalized();
  for (std::size_t f = 0; f < std::size_t(volume_.dims[2]); ++f) {
    const auto at = [&](std::size_t n) { return w[f * per_file + n]; };
    const auto num = [&](std::size_t n) { return std::stod(at(n)); };
    series_uids.insert(at(0));
    instance_uids.insert(at(1));
    EXPECT_EQ(at(2), "P123");
    const int k = std::stoi(at(3)) - 1;
    const Eigen::Vector3d expected_mm = volume_.world_of_index({0, 0, double(k)}) * 1e3;
    EXPECT_LT((Eigen::Vector3d(num(4), num(5), num(6)) - expected_mm).norm(), 1e-6)
        << "slice " << k;
    EXPECT_LT((Eigen::Vector3d(num(7), num(8), num(9)) - row_direction).norm(), 1e-9);
    EXPECT_NEAR(num(10), 0.9, 1e-12) << "PixelSpacing[0] is the row spacing (along j)";
    EXPECT_NEAR(num(11), 0.7, 1e-12) << "PixelSpacing[1] is the column spacing (along i)";
    EXPECT_EQ(num(12), std::round(volume_.values[volume_.linear_index(2, 1, k)]));
  }
  EXPECT_EQ(series_uids.size(), 1u);
  EXPECT_NE(*series_uids.begin(), volume_.dicom_tags.at("source_series_uid"));
  EXPECT_EQ(instance_uids.size(), std::size_t(volume_.dims[2]));
}

TEST_F(DicomSeriesTest, FileNamesDoNotMatter) {
  const ImageVolume before = read_dicom_series(series_.string());
  std::mt19937 random(20240611);
  std::vector<fs::path> files = files_in(series_);
  std::shuffle(files.begin(), files.end(), random);
  for (std::size_t n = 0; n < files.size(); ++n)  // reversed names, and no extension
    fs::rename(files[n], series_ / ("x" + std::to_string(files.size() - n)));
  expect_same_volume(read_dicom_series(series_.string()), before);
}

TEST_F(DicomSeriesTest, OtherFilesInTheFolderAreSkipped) {
  const ImageVolume before = read_dicom_series(series_.string());
  FILE* text = std::fopen((series_ / "README.txt").c_str(), "w");
  ASSERT_NE(text, nullptr);
  std::fputs("not a DICOM file\n", text);
  std::fclose(text);
  fs::create_directory(series_ / "subfolder");
  expect_same_volume(read_dicom_series(series_.string()), before);
}

TEST_F(DicomSeriesTest, MissingSliceIsAGapUnlessAllowed) {
  fs::remove(files_in(series_)[2]);
  const std::string message = error_of([&] { read_dicom_series(series_.string()); });
  EXPECT_NE(message.find("gap of 5 mm"), std::string::npos) << message;
  EXPECT_NE(message.find("median gap is 2.5 mm"), std::string::npos) << message;

  std::vector<std::string> warnings;
  const ImageVolume v = read_dicom_series(series_.string(), "", true, &warnings);
  EXPECT_EQ(v.dims[2], volume_.dims[2] - 1);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("gap"), std::string::npos) << warnings[0];
  EXPECT_NEAR(v.spacing_m()[2], 2.5e-3, 1e-9);
}

TEST_F(DicomSeriesTest, DuplicatePositionIsAnError) {
  fs::copy_file(files_in(series_)[1], series_ / "copy.dcm");
  const std::string message = error_of([&] { read_dicom_series(series_.string()); });
  EXPECT_NE(message.find("duplicate slice position"), std::string::npos) << message;
}

TEST_F(DicomSeriesTest, TwoSeriesNeedAChoice) {
  const fs::path other = tmp_ / "other";
  write_dicom_series(other.string(), oblique_volume(3), "second");
  const fs::path mixed = tmp_ / "mixed";
  copy_folder(series_, mixed);
  for (const auto& file : files_in(other))
    fs::copy_file(file, mixed / ("b" + file.filename().string()));

  const auto series = list_dicom_series(mixed.string());
  ASSERT_EQ(series.size(), 2u);
  const std::string message = error_of([&] { read_dicom_series(mixed.string()); });
  for (const auto& s : series) {
    EXPECT_NE(message.find(s.series_uid), std::string::npos) << message;
    EXPECT_NE(message.find(std::to_string(s.files) + " files"), std::string::npos) << message;
    EXPECT_NE(message.find(s.description), std::string::npos) << message;
  }
  EXPECT_NE(message.find("--series UID"), std::string::npos) << message;

  for (const auto& s : series)
    EXPECT_EQ(read_dicom_series(mixed.string(), s.series_uid).dims[2], s.files);
  const std::string unknown = error_of([&] { read_dicom_series(mixed.string(), "1.2.3"); });
  EXPECT_NE(unknown.find("no series 1.2.3"), std::string::npos) << unknown;
}

/// A file cut anywhere after its "DICM" mark, inside an attribute or between two, is an error
/// naming it (DCMTK itself accepts cuts between attributes). Cut alone in a folder, for speed.
TEST_F(DicomSeriesTest, TruncatedFileIsNamed) {
  const fs::path whole = files_in(series_)[3];
  std::ifstream in(whole, std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
  const fs::path victim = tmp_ / "cut" / whole.filename();
  fs::create_directories(victim.parent_path());
  for (std::size_t length = 132; length < bytes.size(); ++length) {
    fs::remove(victim);  // a new file: truncating one in place makes ext4 flush it, slowly
    std::ofstream(victim, std::ios::binary).write(bytes.data(), std::streamsize(length));
    const std::string message = error_of([&] { read_dicom_series(victim.parent_path().string()); });
    ASSERT_NE(message.find(victim.string()), std::string::npos)
        << "cut at " << length << " of " << bytes.size() << " bytes: " << message;
  }
}

TEST_F(DicomSeriesTest, NonCtModalityIsRefusedUnlessAccepted) {
  if (!have_tool("dcmodify")) GTEST_SKIP() << "dcmodify missing (Debian package dcmtk)";
  for (const auto& file : files_in(series_))
    ASSERT_EQ(run_command("dcmodify -nb -m '(0008,0060)=MR' " + quoted(file) + " 2>&1").exit_code,
              0);
  const std::string message = error_of([&] { read_dicom_series(series_.string()); });
  EXPECT_NE(message.find("not a CT series (modality MR)"), std::string::npos) << message;

  DicomReadOptions any;
  any.accept_any_modality = true;
  const ImageVolume v = read_dicom_series(series_.string(), any);
  EXPECT_EQ(v.modality, "MR");
  EXPECT_EQ(v.values, rounded(volume_.values));
}

TEST_F(DicomSeriesTest, MixedOrientationIsAnError) {
  if (!have_tool("dcmodify")) GTEST_SKIP() << "dcmodify missing (Debian package dcmtk)";
  const fs::path odd = files_in(series_)[2];
  ASSERT_EQ(run_command("dcmodify -nb -m '(0020,0037)=0\\1\\0\\1\\0\\0' " + quoted(odd) + " 2>&1")
                .exit_code,
            0);
  const std::string message = error_of([&] { read_dicom_series(series_.string()); });
  EXPECT_NE(message.find("mixed ImageOrientationPatient"), std::string::npos) << message;
  EXPECT_NE(message.find(odd.filename().string()), std::string::npos) << message;
}

/// DCMTK's tools re-encode the written files (compressed, other byte orders and VRs, bare
/// datasets without preamble and meta header); every form must give back the same volume.
TEST_F(DicomSeriesTest, ReencodedSeriesReadAlike) {
  const ImageVolume plain = read_dicom_series(series_.string());
  const std::vector<std::pair<std::string, std::string>> encodings = {
      {"jpeg_lossless", "dcmcjpeg +e1"},  // JPEG lossless, first-order prediction
      {"jpeg_ls", "dcmcjpls +el"},        // JPEG-LS lossless
      {"rle", "dcmcrle"},
      {"big_endian", "dcmconv +tb"},
      {"deflated", "dcmconv +td"},
      {"implicit_bare", "dcmconv +ti -F"}};
  for (const auto& [name, command] : encodings) {
    const std::string tool = command.substr(0, command.find(' '));
    if (!have_tool(tool)) GTEST_SKIP() << tool << " missing (Debian package dcmtk)";
    const fs::path encoded = tmp_ / name;
    fs::create_directories(encoded);
    for (const auto& file : files_in(series_))
      ASSERT_EQ(run_command(command + " " + quoted(file) + " " + quoted(encoded / file.filename()) +
                            " 2>&1")
                    .exit_code,
                0)
          << command;
    const ImageVolume v = read_dicom_series(encoded.string());
    EXPECT_EQ(v.dims, plain.dims) << name;
    EXPECT_TRUE(v.affine_lps_m.isApprox(plain.affine_lps_m, 1e-12)) << name;
    EXPECT_EQ(v.values, plain.values) << name;
  }
}

// ---- writer rules ----------------------------------------------------------------------------

TEST(DicomWrite, RefusesNonEmptyFolder) {
  TempDir tmp;
  const fs::path out = tmp / "out";
  fs::create_directories(out);
  FILE* f = std::fopen((out / "keep.txt").c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fclose(f);
  const std::string message =
      error_of([&] { write_dicom_series(out.string(), oblique_volume(), "x"); });
  EXPECT_NE(message.find("not an empty folder"), std::string::npos) << message;
  EXPECT_EQ(files_in(out).size(), 1u);
  EXPECT_EQ(files_in(tmp.path()).size(), 1u) << "no staging folder left behind";

  fs::remove(out / "keep.txt");  // an empty folder is fine
  write_dicom_series(out.string(), oblique_volume(), "x");
  EXPECT_EQ(files_in(out).size(), 6u);
}

TEST(DicomWrite, ReplaceSwapsAnEarlierSeriesWhole) {
  TempDir tmp;
  const fs::path out = tmp / "series";
  replace_dicom_series(out.string(), oblique_volume(6), "first");  // a new folder
  ASSERT_EQ(files_in(out).size(), 6u);

  ImageVolume second = oblique_volume(4);  // fewer slices: no slice of the first may survive
  for (float& v : second.values) v += 100.f;
  replace_dicom_series(out.string(), second, "second");
  EXPECT_EQ(files_in(out).size(), 4u);
  EXPECT_EQ(read_dicom_series(out.string()).values, rounded(second.values));
  EXPECT_EQ(files_in(tmp.path()).size(), 1u) << "no staging or old folder left behind";
}

TEST(DicomWrite, ReplaceRefusesAFolderWithOtherFiles) {
  TempDir tmp;
  const fs::path out = tmp / "series";
  replace_dicom_series(out.string(), oblique_volume(3), "x");
  for (const char* foreign : {"notes.txt", "CT00001.dcm.bak", "sub"}) {
    const fs::path path = out / foreign;
    if (std::string(foreign) == "sub") fs::create_directory(path);
    else std::fclose(std::fopen(path.c_str(), "w"));
    for (const std::string& message :
         {error_of([&] { check_dicom_series_replaceable(out.string()); }),
          error_of([&] { replace_dicom_series(out.string(), oblique_volume(5), "y"); })}) {
      EXPECT_NE(message.find(std::string("'") + foreign + "'"), std::string::npos) << message;
      EXPECT_NE(message.find("not a slice of an earlier VoxBreast series"), std::string::npos) << message;
    }
    EXPECT_EQ(files_in(out).size(), 4u) << foreign << ": the folder is left as it was";
    EXPECT_EQ(files_in(tmp.path()).size(), 1u) << foreign << ": no staging folder left behind";
    fs::remove(path);
  }
  check_dicom_series_replaceable(out.string());  // its own series alone is fine

  const fs::path file = tmp / "plain_file";
  std::fclose(std::fopen(file.c_str(), "w"));
  EXPECT_NE(error_of([&] { replace_dicom_series(file.string(), oblique_volume(), "x"); }).find("is not a folder"),
            std::string::npos);
}

TEST(DicomWrite, RefusesShearedAffine) {
  TempDir tmp;
  ImageVolume v = oblique_volume();
  v.affine_lps_m(0, 2) += 0.5e-3;  // k axis leans along x
  const std::string message = error_of([&] { write_dicom_series((tmp / "out").string(), v, "x"); });
  EXPECT_NE(message.find("sheared"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(tmp / "out"));
  EXPECT_TRUE(files_in(tmp.path()).empty()) << "no staging folder left behind";
}

/// A left-handed volume (k against row × column) is written at its true positions; it reads
/// back with k reversed, so every voxel keeps its world position and value.
TEST(DicomWrite, LeftHandedVolumeKeepsWorldPositions) {
  TempDir tmp;
  ImageVolume v = oblique_volume();
  v.affine_lps_m.block<3, 1>(0, 2) *= -1;
  write_dicom_series((tmp / "out").string(), v, "left-handed");
  const ImageVolume back = read_dicom_series((tmp / "out").string());
  ASSERT_EQ(back.dims, v.dims);
  const int last = v.dims[2] - 1;
  for (int k = 0; k <= last; ++k)
    for (int j : {0, v.dims[1] - 1})
      for (int i : {0, 5}) {
        const Eigen::Vector3d ijk(i, j, k), mirrored(i, j, last - k);
        EXPECT_LT((back.world_of_index(mirrored) - v.world_of_index(ijk)).norm(), 1e-6);
        EXPECT_EQ(back.values[back.linear_index(i, j, last - k)],
                  std::round(v.values[v.linear_index(i, j, k)]));
      }
}

TEST(DicomWrite, SingleSliceUsesItsThickness) {
  TempDir tmp;
  const ImageVolume v = oblique_volume(1);
  write_dicom_series((tmp / "out").string(), v, "one slice");
  const ImageVolume back = read_dicom_series((tmp / "out").string());
  EXPECT_EQ(back.dims, v.dims);
  EXPECT_LT((back.affine_lps_m - v.affine_lps_m).cwiseAbs().maxCoeff(), 1e-6);
}

/// Without source attributes (NIfTI, phantom) the writer starts a study with default patient.
TEST(DicomWrite, DefaultsWithoutSourceTags) {
  TempDir tmp;
  ImageVolume v = oblique_volume(2);
  v.dicom_tags.clear();
  write_dicom_series((tmp / "out").string(), v, "phantom");
  const ImageVolume back = read_dicom_series((tmp / "out").string());
  EXPECT_EQ(back.dicom_tags.at("0010,0010"), "VoxBreast^Phantom");
  EXPECT_EQ(back.dicom_tags.at("0010,0020"), "VOXBREAST");
  EXPECT_FALSE(back.dicom_tags.at("0020,000D").empty());
  EXPECT_FALSE(back.dicom_tags.at("0020,0052").empty());
}

TEST(DicomWrite, PatientPositionFollowsGravity) {
  EXPECT_EQ(dicom_patient_position({0, 9.8, 0}), "HFS");   // gravity towards the back: supine
  EXPECT_EQ(dicom_patient_position({0, -9.8, 0}), "HFP");  // prone
  EXPECT_EQ(dicom_patient_position({9.8, 0, 0}), "HFDL");  // towards the left: on the left side
  EXPECT_EQ(dicom_patient_position({-9.8, 0, 0}), "HFDR");
  EXPECT_EQ(dicom_patient_position({0, 9.0, 3.0}), "HFS");  // a tilted supine is still supine
  EXPECT_EQ(dicom_patient_position({0, 0, -9.8}), "");      // upright: PatientPosition cannot say
  EXPECT_EQ(dicom_patient_position({0, 0, 0}), "");
}

/// The same volume written twice deterministically gives the same bytes; another voxel value,
/// other UIDs. Without `deterministic`, every write has its own UIDs and dates.
TEST(DicomWrite, DeterministicSeriesAreByteIdentical) {
  TempDir tmp;
  ImageVolume v = oblique_volume(3);
  v.dicom_tags.clear();
  DicomSeriesOptions options;
  options.series_description = "phantom";
  options.patient_position = "HFS";
  options.deterministic = true;
  const WrittenDicomSeries a = write_dicom_series((tmp / "a").string(), v, options);
  const WrittenDicomSeries b = write_dicom_series((tmp / "b").string(), v, options);
  EXPECT_EQ(a.series_uid, b.series_uid);
  EXPECT_EQ(a.instance_uids, b.instance_uids);
  EXPECT_EQ(a.series_uid.rfind("2.25.", 0), 0u) << a.series_uid;
  EXPECT_EQ(std::set<std::string>(a.instance_uids.begin(), a.instance_uids.end()).size(), 3u);
  for (const fs::path& file : files_in(tmp / "a")) {
    std::ifstream x(file, std::ios::binary), y(tmp / "b" / file.filename(), std::ios::binary);
    const std::string bx((std::istreambuf_iterator<char>(x)), {}), by((std::istreambuf_iterator<char>(y)), {});
    EXPECT_TRUE(bx == by) << file.filename();
  }
  v.values[4] += 1;
  const WrittenDicomSeries c = write_dicom_series((tmp / "c").string(), v, options);
  EXPECT_NE(c.series_uid, a.series_uid);
  EXPECT_NE(c.study_uid, a.study_uid);
  options.deterministic = false;
  EXPECT_NE(write_dicom_series((tmp / "d").string(), v, options).series_uid,
            write_dicom_series((tmp / "e").string(), v, options).series_uid);
  if (!have_tool("dcmdump")) GTEST_SKIP() << "dcmdump (DCMTK) is not installed";
  const std::string fixed = run_command("dcmdump " + quoted(tmp / "a" / "CT00001.dcm")).output;
  EXPECT_NE(fixed.find("[HFS]"), std::string::npos);
  EXPECT_EQ(fixed.find("SeriesDate"), std::string::npos);  // no date in a deterministic series
  EXPECT_NE(run_command("dcmdump " + quoted(tmp / "d" / "CT00001.dcm")).output.find("SeriesDate"), std::string::npos);
}

/// A series derived from a read one names, per slice, the read slices it samples.
TEST_F(DicomSeriesTest, SourceImageSequenceNamesTheInputSlices) {
  const ImageVolume source = read_dicom_series(series_.string());
  DicomSeriesOptions options;
  options.series_description = "derived";
  for (int k = 0; k < source.dims[2]; ++k) options.source_slices.push_back({k, std::min(k + 1, source.dims[2] - 1)});
  const fs::path derived = tmp_ / "derived";
  write_dicom_series(derived.string(), source, options);
  if (!have_tool("dcmdump")) GTEST_SKIP() << "dcmdump (DCMTK) is not installed";
  const auto source_uid = [&](int k) {
    return run_command("dcmdump +P SOPInstanceUID " + quoted(series_ / ("CT0000" + std::to_string(k + 1) + ".dcm")))
        .output;
  };
  const std::string second = run_command("dcmdump +P ReferencedSOPInstanceUID " + quoted(derived / "CT00002.dcm")).output;
  const auto uid_in = [](const std::string& line) { return line.substr(line.find('[') + 1, line.find(']') - line.find('[') - 1); };
  EXPECT_NE(second.find(uid_in(source_uid(1))), std::string::npos) << second;
  EXPECT_NE(second.find(uid_in(source_uid(2))), std::string::npos) << second;
  EXPECT_EQ(second.find(uid_in(source_uid(0))), std::string::npos) << second;
  // A volume not read from DICOM has no slices to name.
  ImageVolume plain = volume_;
  plain.dicom_tags.clear();
  EXPECT_THROW(write_dicom_series((tmp_ / "plain").string(), plain, options), Error);
}

/// Values beyond int16 with intercept −1024 get a fitted slope: still within half a step.
TEST(DicomWrite, WideRangeGetsAFittedSlope) {
  TempDir tmp;
  ImageVolume v = oblique_volume(2);
  v.values.front() = -60000.0f;
  v.values.back() = 90000.0f;
  write_dicom_series((tmp / "out").string(), v, "wide");
  const ImageVolume back = read_dicom_series((tmp / "out").string());
  const double step = (90000.0 + 60000.0) / 65535.0;
  for (std::size_t n = 0; n < v.values.size(); ++n)
    ASSERT_NEAR(back.values[n], v.values[n], 0.5 * step + 1e-3) << "voxel " << n;
}

// ---- fuzzing regressions (tests/fuzz/regressions/: slice files as the fuzzer wrote them) -----

const fs::path kRegressions = fs::path(VOXBREAST_SOURCE_DIR) / "tests" / "fuzz" / "regressions";

std::string regression_bytes(const std::string& name) {
  std::ifstream in(kRegressions / name, std::ios::binary);
  EXPECT_TRUE(in) << kRegressions / name;
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// `bytes` with the value of the explicit VR little endian US attribute (group,element) replaced.
std::string with_us(std::string bytes, unsigned group, unsigned element, unsigned value) {
  const std::string key = {char(group & 0xff), char(group >> 8), char(element & 0xff),
                           char(element >> 8),  'U',              'S',
                           2,                   0};
  const std::size_t at = bytes.find(key);
  EXPECT_NE(at, std::string::npos) << "no US attribute " << group << "," << element;
  if (at == std::string::npos) return bytes;
  bytes[at + 8] = char(value & 0xff);
  bytes[at + 9] = char(value >> 8);
  return bytes;
}

std::uint64_t peak_rss_bytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return std::uint64_t(usage.ru_maxrss) * 1024;  // Linux: kilobytes
}

/// Reads a folder holding one slice file with these bytes; the read must fail without raising
/// this process's peak resident memory by more than 64 MiB (it reads no more than the header
/// promises). Its message.
std::string cheap_failure(const std::string& bytes, fs::path& slice) {
  static std::atomic<int> counter{0};
  static TempDir tmp;
  const fs::path dir = tmp / ("case" + std::to_string(counter++));
  fs::create_directories(dir);
  slice = dir / "slice.dcm";
  std::ofstream(slice, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
  const std::uint64_t peak = peak_rss_bytes();
  const std::string message = error_of([&] { read_dicom_series(dir.string()); });
  EXPECT_LT(peak_rss_bytes() - peak, std::uint64_t(64) << 20);
  return message;
}

/// Rows = Columns = 65535 with 12 bytes of pixel data made read_dicom_series allocate 17 GB for
/// the volume (std::bad_alloc escaped). Now the voxel count is capped and each slice's pixel data
/// length is checked against Rows × Columns before the volume is allocated.
TEST(DicomRead, FuzzRegressionHugeRowsColumns) {
  const std::string bytes = regression_bytes("dicom_rows_columns_65535.dcm");
  fs::path slice;
  std::string message = cheap_failure(bytes, slice);
  EXPECT_NE(message.find(slice.parent_path().string() + ": the series has 4294836225 voxels"),
            std::string::npos)
      << message;

  const std::string under_cap = with_us(with_us(bytes, 0x0028, 0x0010, 30000), 0x0028, 0x0011,
                                        30000);  // 9e8 voxels: only the length check stops it
  message = cheap_failure(under_cap, slice);
  EXPECT_NE(message.find(slice.string() + ": pixel data too short: 12 bytes for 30000 x 30000"),
            std::string::npos)
      << message;
}

/// A JPEG lossless slice claiming 65 samples per pixel and 32775 rows was decoded by DCMTK into a
/// 660 MB buffer, copied again, and read as a 155 x 32775 volume. Now the pixel attributes are
/// checked before decoding, and so is the size of the compressed frame against Rows × Columns.
TEST(DicomRead, FuzzRegressionCompressedSliceCheckedBeforeDecoding) {
  const std::string bytes = regression_bytes("dicom_jpeg_65_samples.dcm");
  fs::path slice;
  std::string message = cheap_failure(bytes, slice);
  EXPECT_NE(message.find(slice.string() + ": only greyscale images (SamplesPerPixel 1)"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("SamplesPerPixel 65"), std::string::npos) << message;

  // One sample: DCMTK would decode the 2 x 3 frame into a 155 x 32775 buffer without complaint.
  const std::string one_sample = with_us(bytes, 0x0028, 0x0002, 1);
  message = cheap_failure(one_sample, slice);
  EXPECT_NE(message.find(slice.string() + ": the compressed frame is 2 x 3 pixels"),
            std::string::npos)
      << message;

  // 65535 x 32768 pixels from 1.4 kB of JPEG: refused before DCMTK allocates 4 GiB for them.
  const std::string huge = with_us(with_us(one_sample, 0x0028, 0x0010, 32768), 0x0028, 0x0011,
                                   65535);
  message = cheap_failure(huge, slice);
  EXPECT_NE(message.find(slice.string() + ": compressed pixel data in a file of"),
            std::string::npos)
      << message;

  std::string colour = one_sample;
  const std::size_t photometric = colour.find("MONOCHROME2 ");
  ASSERT_NE(photometric, std::string::npos);
  colour.replace(photometric, 12, "YBR_FULL_422");
  message = cheap_failure(colour, slice);
  EXPECT_NE(message.find(slice.string() + ": only greyscale images (PhotometricInterpretation"),
            std::string::npos)
      << message;

  message = cheap_failure(with_us(one_sample, 0x0028, 0x0100, 12), slice);
  EXPECT_NE(message.find(slice.string() + ": unsupported pixel layout (BitsAllocated 12"),
            std::string::npos)
      << message;
}

/// DCMTK reads a deflated dataset through zlib and allocates each value as long as its length
/// field says before it finds the stream too short (4 GiB for these 0.9 kB files, hand-made from
/// the fuzzing seed). The deflated dataset is now walked first; a length that the data does not
/// back is an error naming the file, found both when the folder is scanned and when it is read.
TEST(DicomRead, DeflatedDatasetLengthsAreCheckedBeforeDcmtkReadsThem) {
  for (const std::string name :
       {"dicom_deflated_pixel_length_4gib.dcm", "dicom_deflated_private_length_4gib.dcm"}) {
    fs::path slice;
    const std::string message = cheap_failure(regression_bytes(name), slice);
    EXPECT_NE(message.find(slice.string() + ": cannot parse DICOM file: the deflated dataset is "
                                            "corrupt or truncated"),
              std::string::npos)
        << name << ": " << message;
    const std::string listed = error_of([&] { list_dicom_series(slice.parent_path().string()); });
    EXPECT_NE(listed.find("the deflated dataset is corrupt"), std::string::npos) << listed;
  }
}

/// A deflated dataset has no checksum; what it has is the deflate stream's own end (its final
/// block). A file cut a few bytes short of it inflated all its attributes and read as complete.
/// Such a stream is now refused, and so is one whose bits are corrupt.
TEST_F(DicomSeriesTest, DeflatedStreamMustEndCleanly) {
  if (!have_tool("dcmconv")) GTEST_SKIP() << "dcmconv missing (Debian package dcmtk)";
  const fs::path first = files_in(series_).front();
  const fs::path deflated = tmp_ / "deflated.dcm";
  ASSERT_EQ(run_command("dcmconv +td " + quoted(first) + " " + quoted(deflated) + " 2>&1").exit_code, 0);
  std::ifstream in(deflated, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  ASSERT_GT(bytes.size(), 64u);
  for (std::size_t cut = 1; cut <= 4; ++cut) {
    SCOPED_TRACE("cut " + std::to_string(cut));
    fs::path slice;
    const std::string message = cheap_failure(bytes.substr(0, bytes.size() - cut), slice);
    EXPECT_NE(message.find("the deflated dataset is corrupt or truncated"), std::string::npos) << message;
  }
}

TEST(DicomRead, FolderErrors) {
  TempDir tmp;
  EXPECT_NE(error_of([&] { read_dicom_series((tmp / "absent").string()); }).find("not a folder"),
            std::string::npos);
  EXPECT_NE(error_of([&] { read_dicom_series(tmp.path().string()); }).find("no DICOM series"),
            std::string::npos);
  EXPECT_TRUE(list_dicom_series(tmp.path().string()).empty());
}

}  // namespace
}  // namespace vb
