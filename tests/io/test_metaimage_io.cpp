// MetaImage displacement fields: the header ITK reads, the zlib data in LPS mm, the refusals;
// the image statistics that summary.json reports beside them.
#include <gtest/gtest.h>
#include <zlib.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "engine/error.hpp"
#include "engine/image/displacement_stats.hpp"
#include "engine/image/source_slices.hpp"
#include "io/metaimage_io.hpp"

namespace vb {
namespace {

namespace fs = std::filesystem;

ImageVolume oblique_grid() {
  ImageVolume grid;
  grid.dims = {5, 4, 3};
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  grid.affine_lps_m.topLeftCorner<3, 3>() = rotation * Eigen::Vector3d(0.7e-3, 0.9e-3, 2.5e-3).asDiagonal();
  grid.affine_lps_m.topRightCorner<3, 1>() = Eigen::Vector3d(-0.12, 0.034, 0.2);
  return grid;
}

std::vector<float> sample_field(const ImageVolume& grid) {
  std::vector<float> u(3 * grid.voxel_count());
  for (std::size_t n = 0; n < u.size(); ++n) u[n] = float(1e-3 * (double(n % 7) - 2.5) * (n % 3 + 1));
  return u;
}

struct MetaFile {
  std::map<std::string, std::string> header;
  std::vector<float> data;
};

MetaFile read_meta(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string last = "ElementDataFile = LOCAL\n";
  const std::size_t end = bytes.find(last) + last.size();
  MetaFile file;
  std::istringstream lines(bytes.substr(0, end));
  for (std::string line; std::getline(lines, line);) {
    const std::size_t eq = line.find(" = ");
    file.header[line.substr(0, eq)] = line.substr(eq + 3);
  }
  std::istringstream dims(file.header["DimSize"]);
  std::size_t nx = 0, ny = 0, nz = 0;
  dims >> nx >> ny >> nz;
  file.data.resize(3 * nx * ny * nz);
  uLongf size = uLongf(file.data.size() * sizeof(float));
  EXPECT_EQ(file.header["CompressedData"], "True");
  EXPECT_EQ(std::stoull(file.header["CompressedDataSize"]), bytes.size() - end);
  EXPECT_EQ(uncompress(reinterpret_cast<Bytef*>(file.data.data()), &size,
                       reinterpret_cast<const Bytef*>(bytes.data() + end), uLong(bytes.size() - end)),
            Z_OK);
  EXPECT_EQ(size, file.data.size() * sizeof(float));
  return file;
}

std::vector<double> numbers(const std::string& text) {
  std::istringstream in(text);
  std::vector<double> values;
  for (double v; in >> v;) values.push_back(v);
  return values;
}

class MetaImage : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("vb_mha_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                        "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(MetaImage, HeaderGivesItkTheGridAndDataAreLpsMillimetres) {
  const ImageVolume grid = oblique_grid();
  const std::vector<float> u = sample_field(grid);
  write_metaimage_displacement(path("u.mha"), grid, u);
  const MetaFile file = read_meta(path("u.mha"));
  EXPECT_EQ(file.header.at("ObjectType"), "Image");
  EXPECT_EQ(file.header.at("ElementType"), "MET_FLOAT");
  EXPECT_EQ(file.header.at("ElementNumberOfChannels"), "3");
  EXPECT_EQ(file.header.at("BinaryDataByteOrderMSB"), "False");
  EXPECT_EQ(numbers(file.header.at("DimSize")), (std::vector<double>{5, 4, 3}));
  const std::vector<double> spacing = numbers(file.header.at("ElementSpacing"));
  const std::vector<double> offset = numbers(file.header.at("Offset"));
  const std::vector<double> matrix = numbers(file.header.at("TransformMatrix"));
  ASSERT_EQ(matrix.size(), 9u);
  for (int a = 0; a < 3; ++a) {
    const Eigen::Vector3d axis_mm = grid.affine_lps_m.block<3, 1>(0, a) * 1e3;
    EXPECT_NEAR(spacing[std::size_t(a)], axis_mm.norm(), 1e-12);
    EXPECT_NEAR(offset[std::size_t(a)], grid.affine_lps_m(a, 3) * 1e3, 1e-12);
    for (int r = 0; r < 3; ++r)  // axis a's direction, in turn: ITK's direction column a
      EXPECT_NEAR(matrix[std::size_t(3 * a + r)], axis_mm[r] / axis_mm.norm(), 1e-12) << "axis " << a;
  }
  ASSERT_EQ(file.data.size(), u.size());
  for (std::size_t n = 0; n < u.size(); ++n) ASSERT_FLOAT_EQ(file.data[n], 1e3f * u[n]) << n;
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);  // atomic: nothing else
}

/// A field of many compressed blocks (deflated on all cores, written in order): still one zlib
/// stream whose Adler-32 holds, and CompressedDataSize (filled in after the data) its exact size;
/// progress reaches 1.
TEST_F(MetaImage, LargeFieldIsOneZlibStreamOfTheStatedSize) {
  ImageVolume grid;
  grid.dims = {90, 80, 70};  // 6 MB of floats: six blocks
  grid.affine_lps_m.topLeftCorner<3, 3>() = 1e-3 * Eigen::Matrix3d::Identity();
  std::vector<float> u(3 * grid.voxel_count());
  for (std::size_t n = 0; n < u.size(); ++n) u[n] = n % 5 == 0 ? 0.f : float(1e-5 * double(n % 1013) - 0.004);
  double last = -1;
  write_metaimage_displacement(path("large.mha"), grid, u, [&](double f) {
    EXPECT_GE(f, last);
    last = f;
  });
  EXPECT_DOUBLE_EQ(last, 1.0);
  const MetaFile file = read_meta(path("large.mha"));  // checks the size and that zlib inflates it whole
  ASSERT_EQ(file.data.size(), u.size());
  for (std::size_t n = 0; n < u.size(); ++n) ASSERT_FLOAT_EQ(file.data[n], float(double(u[n]) * 1e3)) << n;
}

TEST_F(MetaImage, RefusesShearNonFiniteValuesWrongSizesAndOtherNames) {
  ImageVolume grid = oblique_grid();
  std::vector<float> u = sample_field(grid);
  EXPECT_THROW(write_metaimage_displacement(path("u.nii"), grid, u), Error);
  EXPECT_THROW(write_metaimage_displacement(path("u.mha"), grid, std::vector<float>(7)), Error);
  u[3 * 7 + 1] = NAN;
  try {
    write_metaimage_displacement(path("u.mha"), grid, u);
    ADD_FAILURE() << "a NaN was written";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("voxel (2, 1, 0)"), std::string::npos) << e.what();
  }
  u[3 * 7 + 1] = 0;
  grid.affine_lps_m(0, 1) += 0.3e-3;  // shear
  EXPECT_THROW(write_metaimage_displacement(path("u.mha"), grid, u), Error);
  EXPECT_FALSE(fs::exists(path("u.mha")));
}

TEST(DisplacementStats, PerComponentAndLengthOverEveryVoxel) {
  const std::vector<float> u = {0.001f, -0.002f, 0.0f, -0.003f, 0.002f, 0.004f, 0, 0, 0};  // 3 voxels, m
  const DisplacementStats s = displacement_stats(u);
  EXPECT_NEAR(s.min_mm[0], -3, 1e-6);
  EXPECT_NEAR(s.max_mm[2], 4, 1e-6);
  EXPECT_NEAR(s.mean_mm[0], -2.0 / 3, 1e-6);
  EXPECT_NEAR(s.mean_abs_mm[1], 4.0 / 3, 1e-6);
  EXPECT_NEAR(s.mean_length_mm, (std::sqrt(5.0) + std::sqrt(29.0)) / 3, 1e-6);
  EXPECT_NEAR(s.max_length_mm, std::sqrt(29.0), 1e-6);
}

TEST(SourceSlices, ThePulledBackPointsSlicesAreListed) {
  ImageVolume grid;
  grid.dims = {2, 1, 5};
  grid.affine_lps_m.topLeftCorner<3, 3>() = Eigen::Vector3d(1e-3, 1e-3, 2e-3).asDiagonal();
  std::vector<float> d(3 * grid.voxel_count(), 0.f);
  d[3 * grid.linear_index(1, 0, 1) + 2] = 3e-3f;   // slice 1 reads k = 2.5: slices 2 and 3
  d[3 * grid.linear_index(0, 0, 4) + 2] = -1.9e-3f;  // slice 4 reads k = 3.05: slices 3 and 4
  d[3 * grid.linear_index(0, 0, 0) + 2] = -5e-3f;  // slice 0 reads outside: clamped to slice 0
  const auto slices = source_slices_read(grid, d);
  ASSERT_EQ(slices.size(), 5u);
  EXPECT_EQ(slices[0], std::make_pair(0, 0));
  EXPECT_EQ(slices[1], std::make_pair(1, 3));
  EXPECT_EQ(slices[2], std::make_pair(2, 2));
  EXPECT_EQ(slices[4], std::make_pair(3, 4));
}

}  // namespace
}  // namespace vb
