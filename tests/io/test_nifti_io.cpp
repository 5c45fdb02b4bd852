// NIfTI reading and writing: oblique round trips, files from nifti_clib and nibabel, the
// displacement-field convention on disk, and broken files that must throw (not crash).
#include <gtest/gtest.h>
#include <nifti/nifti2_io.h>
#include <sys/resource.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "engine/error.hpp"
#include "engine/image/image_volume.hpp"
#include "io/nifti_io.hpp"

namespace fs = std::filesystem;

namespace vb {
namespace {

const Eigen::Matrix4d kFlipXY = Eigen::Vector4d(-1, -1, 1, 1).asDiagonal();

// ---- fixtures ----------------------------------------------------------------------------------

/// Rotated about a skew axis, anisotropic spacing, origin away from zero: catches any transposed,
/// unflipped or unscaled affine.
ImageVolume oblique_grid() {
  ImageVolume image;
  image.dims = {5, 4, 3};
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  image.affine_lps_m.topLeftCorner<3, 3>() =
      rotation * Eigen::Vector3d(0.7e-3, 0.9e-3, 2.5e-3).asDiagonal();
  image.affine_lps_m.topRightCorner<3, 1>() = Eigen::Vector3d(-0.12, 0.034, 0.2);
  return image;
}

/// The LPS-metre affine as NIfTI RAS mm: diag(-1,-1,1,1) · A, linear part and translation x1000.
Eigen::Matrix4d ras_mm(const Eigen::Matrix4d& affine_lps_m) {
  Eigen::Matrix4d ras = kFlipXY * affine_lps_m;
  ras.topRows<3>() *= 1000.0;
  return ras;
}

/// Values that the type holds exactly after rounding; the .4 offsets test rounding to nearest.
float value_for(NiftiType type, int i, int j, int k) {
  switch (type) {
    case NiftiType::Int16: return -1024.4f + 7.0f * i + 50.0f * j + 300.0f * k;
    case NiftiType::UInt8: return 1.4f + 3.0f * i + 10.0f * j + 60.0f * k;
    case NiftiType::Float32: return 0.25f * i - 3.5f * j + 1000.125f * k;
  }
  return 0.0f;
}

ImageVolume oblique_volume(NiftiType type) {
  ImageVolume image = oblique_grid();
  image.values.resize(image.voxel_count());
  for (int k = 0; k < image.dims[2]; ++k)
    for (int j = 0; j < image.dims[1]; ++j)
      for (int i = 0; i < image.dims[0]; ++i)
        image.values[image.linear_index(i, j, k)] = value_for(type, i, j, k);
  return image;
}

/// u(x) per voxel in LPS metres, all components distinct and signed.
std::vector<float> sample_displacement(const ImageVolume& grid) {
  std::vector<float> u(3 * grid.voxel_count());
  for (std::size_t v = 0; v < grid.voxel_count(); ++v) {
    u[3 * v + 0] = 1e-3f * (0.5f + float(v));
    u[3 * v + 1] = -2e-4f * (1.0f + float(v));
    u[3 * v + 2] = 3e-5f * float(v) - 1e-3f;
  }
  return u;
}

void expect_affine_near(const Eigen::Matrix4d& actual, const Eigen::Matrix4d& expected,
                        double tolerance) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      EXPECT_NEAR(actual(r, c), expected(r, c), tolerance) << "affine(" << r << ", " << c << ")";
}

/// NIfTI-1 stores the sform in float32: about 1e-5 mm on 200 mm, so compare to 1e-7 m.
constexpr double kAffineTolerance_m = 1e-7;

/// A fresh folder per test, removed afterwards.
class NiftiIo : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "-" + info->name();
    for (char& c : name)
      if (c == '/') c = '_';
    dir_ =
        fs::temp_directory_path() / ("voxbreast-nifti-" + std::to_string(::getpid()) + "-" + name);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  /// The function must throw vb::Error whose message names `file` and contains `text`.
  static void expect_error(const std::function<void()>& f, const std::string& file,
                           const std::string& text) {
    try {
      f();
      ADD_FAILURE() << "no vb::Error for " << file;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  }

  fs::path dir_;
};

// ---- files written directly with nifti_clib ----------------------------------------------------

struct NiftiFree {
  void operator()(nifti_image* nim) const { nifti_image_free(nim); }
};

/// What write_raw puts in a file, bypassing our writer.
struct RawSpec {
  std::array<std::int64_t, 8> dim{3, 3, 4, 2, 1, 1, 1, 1};
  int datatype = NIFTI_TYPE_INT16;
  int nifti_type = NIFTI_FTYPE_NIFTI1_1;
  int sform_code = NIFTI_XFORM_SCANNER_ANAT;
  int qform_code = NIFTI_XFORM_UNKNOWN;
  Eigen::Matrix4d ras = ras_mm(oblique_grid().affine_lps_m);  // sform and qform source
  std::array<double, 3> pixdim{0.7, 0.9, 2.5};
  double slope = 0.0, inter = 0.0;
  int xyz_units = NIFTI_UNITS_MM;
};

/// Stored value of voxel v in write_raw's int16 files.
std::int16_t raw_value(std::size_t v) { return std::int16_t(int(v) * 3 - 20); }

/// Header (NIfTI-1 or -2 struct), empty extension flag, voxels; gzip for ".gz". Written by hand
/// because nifti_image_write of nifti_clib 3.0.1 overwrites a single-file NIfTI-2 header.
template <class Header>
void write_with_header(const std::string& path, Header header, const nifti_image& nim,
                       const RawSpec& spec) {
  for (int d = 0; d < 3; ++d) header.pixdim[d + 1] = spec.pixdim[std::size_t(d)];  // even if bad
  header.vox_offset = sizeof header + 4;
  const bool gzip = path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0;
  znzFile file = znzopen(path.c_str(), "wb", gzip ? 1 : 0);
  ASSERT_FALSE(znz_isnull(file)) << path;
  const char no_extension[4] = {0, 0, 0, 0};
  znzwrite(&header, sizeof header, 1, file);
  znzwrite(no_extension, 1, 4, file);
  znzwrite(nim.data, std::size_t(nim.nbyper), std::size_t(nim.nvox), file);
  ASSERT_EQ(znzclose(file), 0) << path;
}

void write_raw(const std::string& path, const RawSpec& spec) {
  std::unique_ptr<nifti_image, NiftiFree> nim(
      nifti_make_new_nim(spec.dim.data(), spec.datatype, /*data_fill=*/1));
  ASSERT_TRUE(nim);
  nim->nifti_type = spec.nifti_type;
  if (spec.datatype == NIFTI_TYPE_INT16)
    for (std::int64_t v = 0; v < nim->nvox; ++v)
      static_cast<std::int16_t*>(nim->data)[v] = raw_value(std::size_t(v));
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) nim->sto_xyz.m[r][c] = spec.ras(r, c);
  nim->sform_code = spec.sform_code;
  nim->qform_code = spec.qform_code;
  double dx, dy, dz;
  nifti_dmat44_to_quatern(nim->sto_xyz, &nim->quatern_b, &nim->quatern_c, &nim->quatern_d,
                          &nim->qoffset_x, &nim->qoffset_y, &nim->qoffset_z, &dx, &dy, &dz,
                          &nim->qfac);
  nim->scl_slope = spec.slope;
  nim->scl_inter = spec.inter;
  nim->xyz_units = spec.xyz_units;
  if (spec.nifti_type == NIFTI_FTYPE_NIFTI2_1) {
    nifti_2_header header{};
    ASSERT_EQ(nifti_convert_nim2n2hdr(nim.get(), &header), 0);
    std::memcpy(header.magic, "n+2\0\r\n\032\n", 8);  // nifti_clib 3.0.1 leaves out the tail
    write_with_header(path, header, *nim, spec);
  } else {
    nifti_1_header header{};
    ASSERT_EQ(nifti_convert_nim2n1hdr(nim.get(), &header), 0);
    write_with_header(path, header, *nim, spec);
  }
}

// ---- nibabel -----------------------------------------------------------------------------------

bool nibabel_available() {
  static const bool available =
      std::system("/usr/bin/python3 -c 'import nibabel' >/dev/null 2>&1") == 0;
  return available;
}

#define REQUIRE_NIBABEL()                                                        \
  do {                                                                           \
    if (!nibabel_available())                                                    \
      GTEST_SKIP() << "/usr/bin/python3 cannot import nibabel; install it with " \
                      "scripts/setup.sh (python3-nibabel)";                      \
  } while (0)

/// Runs a Python script with arguments; returns its stdout, failing the test on a non-zero exit.
std::string run_python(const fs::path& dir, const std::string& script, const std::string& args) {
  const fs::path file = dir / "check.py";
  std::ofstream(file) << script;
  const std::string command = "/usr/bin/python3 " + file.string() + " " + args + " 2>&1";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) {
    ADD_FAILURE() << "cannot run " << command;
    return {};
  }
  std::string out;
  char buffer[4096];
  while (std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe.get())) out.append(buffer, n);
  const int status = pclose(pipe.release());
  EXPECT_EQ(status, 0) << command << "\n" << out;
  return out;
}

/// Lines "key v1 v2 ..." -> key -> numbers.
std::map<std::string, std::vector<double>> parse_lines(const std::string& text) {
  std::map<std::string, std::vector<double>> fields;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string key;
    words >> key;
    for (double x; words >> x;) fields[key].push_back(x);
  }
  return fields;
}

/// Prints what nibabel sees in the file argv[1]; argv[2:] are i j k triples for `voxels`
/// (values after scl_slope/scl_inter; for 5-D files the 3 components of the vector).
const char* const kNibabelDump = R"PY(
import sys
import nibabel as nib
import numpy as np
img = nib.load(sys.argv[1])
h = img.header
def out(key, values):
    print(key, *[repr(float(x)) for x in np.ravel(np.asarray(values, dtype=float))])
out('shape', img.shape)
out('affine', img.affine)
out('qform', img.get_qform())
out('codes', [h['sform_code'], h['qform_code']])
out('xyzt_units', [h['xyzt_units']])
out('intent', [h['intent_code']])
out('nifti2', [isinstance(img, nib.Nifti2Image)])
data = np.asanyarray(img.dataobj)
ijk = [int(a) for a in sys.argv[2:]]
out('voxels', [data[ijk[n], ijk[n + 1], ijk[n + 2]] for n in range(0, len(ijk), 3)])
)PY";

Eigen::Matrix4d as_matrix(const std::vector<double>& row_major) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  if (row_major.size() != 16) {
    ADD_FAILURE() << "expected 16 affine entries, got " << row_major.size();
    return m;
  }
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = row_major[std::size_t(4 * r + c)];
  return m;
}

// ---- round trips -------------------------------------------------------------------------------

class NiftiRoundTrip : public NiftiIo,
                       public ::testing::WithParamInterface<std::tuple<NiftiType, std::string>> {};

TEST_P(NiftiRoundTrip, ObliqueVolumeKeepsGeometryAndRoundedValues) {
  const auto& [type, extension] = GetParam();
  const ImageVolume written = oblique_volume(type);
  const std::string file = path("image" + extension);
  write_nifti(file, written, type);

  const ImageVolume read = read_nifti(file);
  EXPECT_EQ(read.dims, written.dims);
  expect_affine_near(read.affine_lps_m, written.affine_lps_m, kAffineTolerance_m);
  ASSERT_EQ(read.values.size(), written.values.size());
  for (std::size_t v = 0; v < read.values.size(); ++v) {
    const float expected =
        type == NiftiType::Float32 ? written.values[v] : std::round(written.values[v]);
    ASSERT_EQ(read.values[v], expected) << "voxel " << v;
  }
}

std::string case_name(NiftiType type, const std::string& extension) {
  const std::string names[] = {"Int16", "UInt8", "Float32"};
  return names[int(type)] + (extension == ".nii" ? "_nii" : "_nii_gz");
}

INSTANTIATE_TEST_SUITE_P(
    TypesAndExtensions, NiftiRoundTrip,
    ::testing::Combine(::testing::Values(NiftiType::Int16, NiftiType::UInt8, NiftiType::Float32),
                       ::testing::Values(std::string(".nii"), std::string(".nii.gz"))),
    [](const auto& info) { return case_name(std::get<0>(info.param), std::get<1>(info.param)); });

TEST_F(NiftiIo, GzipIsChosenByExtension) {
  const ImageVolume image = oblique_volume(NiftiType::Int16);
  write_nifti(path("a.nii"), image, NiftiType::Int16);
  write_nifti(path("a.nii.gz"), image, NiftiType::Int16);
  unsigned char magic[2] = {0, 0};
  std::ifstream(path("a.nii.gz"), std::ios::binary).read(reinterpret_cast<char*>(magic), 2);
  EXPECT_EQ(magic[0], 0x1f);
  EXPECT_EQ(magic[1], 0x8b);
  EXPECT_EQ(fs::file_size(path("a.nii")), 352u + 2u * image.voxel_count());
  // Nothing else left behind by the atomic writes.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 2);
}

TEST_F(NiftiIo, LabelModalityRoundTripsThroughIntent) {
  ImageVolume labels = oblique_volume(NiftiType::UInt8);
  labels.modality = "LABEL";
  write_nifti(path("labels.nii.gz"), labels, NiftiType::UInt8);
  EXPECT_EQ(read_nifti(path("labels.nii.gz")).modality, "LABEL");
  write_nifti(path("ct.nii.gz"), oblique_volume(NiftiType::Int16), NiftiType::Int16);
  EXPECT_EQ(read_nifti(path("ct.nii.gz")).modality, "");
}

TEST_F(NiftiIo, DisplacementRoundTrip) {
  const ImageVolume grid = oblique_grid();
  const std::vector<float> u = sample_displacement(grid);
  for (const std::string name : {"u.nii", "u.nii.gz"}) {
    write_nifti_displacement(path(name), grid, u);
    std::vector<float> back;
    const ImageVolume read = read_nifti_displacement(path(name), back);
    EXPECT_EQ(read.dims, grid.dims);
    EXPECT_TRUE(read.values.empty());
    expect_affine_near(read.affine_lps_m, grid.affine_lps_m, kAffineTolerance_m);
    ASSERT_EQ(back.size(), u.size());
    for (std::size_t n = 0; n < u.size(); ++n)
      ASSERT_NEAR(back[n], u[n], 1e-6 * std::abs(u[n]) + 1e-12) << name << " float " << n;
  }
}

TEST_F(NiftiIo, LegacyDisplacementLayoutIsIntent1007WithLpsComponents) {
  const ImageVolume grid = oblique_grid();
  const std::vector<float> u = sample_displacement(grid);
  write_nifti_displacement(path("ras.nii"), grid, u);
  write_nifti_displacement(path("lps.nii"), grid, u, NiftiDisplacementLayout::VectorLps);
  const auto header_and_data = [&](const std::string& name) {
    nifti_image* nim = nifti_image_read(path(name).c_str(), 1);
    EXPECT_NE(nim, nullptr);
    const int intent = nim->intent_code;
    std::vector<float> data(static_cast<const float*>(nim->data), static_cast<const float*>(nim->data) + nim->nvox);
    nifti_image_free(nim);
    return std::make_pair(intent, data);
  };
  const auto [ras_intent, ras] = header_and_data("ras.nii");
  const auto [lps_intent, lps] = header_and_data("lps.nii");
  EXPECT_EQ(ras_intent, NIFTI_INTENT_DISPVECT);
  EXPECT_EQ(lps_intent, NIFTI_INTENT_VECTOR);
  const std::size_t n = grid.voxel_count();
  for (std::size_t v = 0; v < n; ++v)
    for (std::size_t c = 0; c < 3; ++c) {
      ASSERT_FLOAT_EQ(lps[c * n + v], 1e3f * u[3 * v + c]) << "voxel " << v;           // LPS mm
      ASSERT_FLOAT_EQ(ras[c * n + v], (c < 2 ? -1e3f : 1e3f) * u[3 * v + c]) << "voxel " << v;  // RAS mm
    }
  std::vector<float> back;  // our reader takes both layouts to the same field
  read_nifti_displacement(path("lps.nii"), back);
  for (std::size_t f = 0; f < u.size(); ++f) ASSERT_NEAR(back[f], u[f], 1e-6 * std::abs(u[f]) + 1e-12);
}

/// Fields of several compressed blocks (written on all cores, each block deflated on its own):
/// one gzip member whose trailer holds the whole size and CRC, as `gzip -t` and Python's gzip
/// (single-member reading: zlib.decompressobj stops after one member) check.
TEST_F(NiftiIo, LargeFieldIsOneGzipMemberReadBackExactly) {
  ImageVolume grid;
  grid.dims = {96, 80, 70};  // 6.4 MB of floats: two blocks and more
  grid.affine_lps_m.topLeftCorner<3, 3>() = 1e-3 * Eigen::Matrix3d::Identity();
  std::vector<float> u(3 * grid.voxel_count());
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> value(-0.02f, 0.02f);
  for (std::size_t n = 0; n < u.size(); ++n) u[n] = n % 7 == 0 ? 0.f : value(rng);
  write_nifti_displacement(path("u.nii.gz"), grid, u);
  std::vector<float> back;
  read_nifti_displacement(path("u.nii.gz"), back);
  ASSERT_EQ(back.size(), u.size());
  for (std::size_t n = 0; n < u.size(); ++n) ASSERT_NEAR(back[n], u[n], 1e-6 * std::abs(u[n])) << n;
  EXPECT_EQ(std::system(("gzip -t " + path("u.nii.gz")).c_str()), 0);
  const std::string one_member =
      "/usr/bin/python3 -c \"import sys,zlib; d=zlib.decompressobj(31); b=d.decompress(open(sys.argv[1],'rb').read()); "
      "sys.exit(0 if d.eof and not d.unused_data and len(b)==352+4*" + std::to_string(u.size()) + " else 1)\" " +
      path("u.nii.gz");
  EXPECT_EQ(std::system(one_member.c_str()), 0);
}

// ---- reading files from elsewhere --------------------------------------------------------------

TEST_F(NiftiIo, ScaleSlopeAndInterceptAreApplied) {
  RawSpec spec;
  spec.slope = 2.0;
  spec.inter = -1024.0;
  write_raw(path("scaled.nii"), spec);
  const ImageVolume image = read_nifti(path("scaled.nii"));
  ASSERT_EQ(image.values.size(), 24u);
  for (std::size_t v = 0; v < image.values.size(); ++v)
    EXPECT_EQ(image.values[v], 2.0f * raw_value(v) - 1024.0f) << v;
}

TEST_F(NiftiIo, ReadsNifti2) {
  RawSpec spec;
  spec.nifti_type = NIFTI_FTYPE_NIFTI2_1;
  spec.slope = 0.5;
  spec.inter = 10.0;
  write_raw(path("two.nii.gz"), spec);
  int version = 0;  // nifti_image.nifti_type says 1 after reading even a NIfTI-2 file
  std::free(nifti_read_header(path("two.nii.gz").c_str(), &version, 1));
  ASSERT_EQ(version, 2);
  const ImageVolume image = read_nifti(path("two.nii.gz"));
  EXPECT_EQ(image.dims, (std::array<int, 3>{3, 4, 2}));
  // NIfTI-2 keeps the sform in double precision.
  expect_affine_near(image.affine_lps_m, oblique_grid().affine_lps_m, 1e-12);
  for (std::size_t v = 0; v < image.values.size(); ++v)
    EXPECT_EQ(image.values[v], 0.5f * raw_value(v) + 10.0f) << v;
}

TEST_F(NiftiIo, QformUsedWithoutSform) {
  RawSpec spec;
  spec.sform_code = NIFTI_XFORM_UNKNOWN;
  spec.qform_code = NIFTI_XFORM_SCANNER_ANAT;
  write_raw(path("qform.nii"), spec);
  expect_affine_near(read_nifti(path("qform.nii")).affine_lps_m, oblique_grid().affine_lps_m,
                     kAffineTolerance_m);
}

TEST_F(NiftiIo, PixdimDiagonalWithoutAnyXform) {
  RawSpec spec;
  spec.sform_code = spec.qform_code = NIFTI_XFORM_UNKNOWN;
  write_raw(path("bare.nii"), spec);
  const Eigen::Matrix4d expected = Eigen::Vector4d(-0.7e-3, -0.9e-3, 2.5e-3, 1).asDiagonal();
  expect_affine_near(read_nifti(path("bare.nii")).affine_lps_m, expected, 1e-9);
}

TEST_F(NiftiIo, SpatialUnitsAreHonoured) {
  RawSpec spec;
  spec.xyz_units = NIFTI_UNITS_METER;
  spec.ras /= 1000.0;  // the same geometry, expressed in metres
  spec.ras(3, 3) = 1.0;
  write_raw(path("metres.nii"), spec);
  expect_affine_near(read_nifti(path("metres.nii")).affine_lps_m, oblique_grid().affine_lps_m,
                     kAffineTolerance_m);
}

// ---- broken input ------------------------------------------------------------------------------

TEST_F(NiftiIo, MissingFile) {
  const std::string file = path("absent.nii.gz");
  expect_error([&] { read_nifti(file); }, file, "not found");
  std::vector<float> u;
  expect_error([&] { read_nifti_displacement(file, u); }, file, "not found");
}

TEST_F(NiftiIo, TruncatedFiles) {
  for (const std::string name : {"cut.nii", "cut.nii.gz"}) {
    const std::string file = path(name);
    ImageVolume image = oblique_grid();
    image.dims = {40, 30, 20};  // enough voxels that gzip output is well past the header
    image.values.assign(image.voxel_count(), 0.0f);
    for (std::size_t v = 0; v < image.values.size(); ++v) image.values[v] = float(v % 997);
    write_nifti(file, image, NiftiType::Float32);
    fs::resize_file(file, fs::file_size(file) * 2 / 3);
    expect_error([&] { read_nifti(file); }, file, "truncated");
    fs::resize_file(file, 200);  // inside the 348-byte header
    expect_error([&] { read_nifti(file); }, file, "header");
  }
}

TEST_F(NiftiIo, RandomBytes) {
  std::mt19937 random(42);
  for (const std::string name : {"noise.nii", "noise.nii.gz"}) {
    const std::string file = path(name);
    std::ofstream out(file, std::ios::binary);
    for (int n = 0; n < 4096; ++n) out.put(char(random() & 0xff));
    out.close();
    expect_error([&] { read_nifti(file); }, file, "NIfTI");
  }
}

TEST_F(NiftiIo, FourDimensionalScalarRefused) {
  RawSpec spec;
  spec.dim = {4, 3, 4, 2, 2, 1, 1, 1};
  write_raw(path("4d.nii"), spec);
  expect_error([&] { read_nifti(path("4d.nii")); }, path("4d.nii"), "dim[4] = 2");
}

TEST_F(NiftiIo, UnsupportedDatatypeRefused) {
  RawSpec spec;
  spec.datatype = NIFTI_TYPE_COMPLEX64;
  write_raw(path("complex.nii"), spec);
  expect_error([&] { read_nifti(path("complex.nii")); }, path("complex.nii"),
               "unsupported voxel type");
}

TEST_F(NiftiIo, BadSpacingOrSingularAffineRefused) {
  RawSpec zero_pixdim;
  zero_pixdim.sform_code = NIFTI_XFORM_UNKNOWN;
  zero_pixdim.qform_code = NIFTI_XFORM_SCANNER_ANAT;
  zero_pixdim.pixdim[1] = 0.0;
  write_raw(path("zero.nii"), zero_pixdim);
  expect_error([&] { read_nifti(path("zero.nii")); }, path("zero.nii"), "pixdim[2] = 0");

  RawSpec negative_pixdim;
  negative_pixdim.sform_code = negative_pixdim.qform_code = NIFTI_XFORM_UNKNOWN;
  negative_pixdim.pixdim[0] = -0.7;
  write_raw(path("negative.nii.gz"), negative_pixdim);
  expect_error([&] { read_nifti(path("negative.nii.gz")); }, path("negative.nii.gz"),
               "not positive");

  RawSpec flat_axis;
  flat_axis.ras.col(2).head<3>().setZero();
  write_raw(path("flat.nii"), flat_axis);
  expect_error([&] { read_nifti(path("flat.nii")); }, path("flat.nii"), "zero voxel spacing");

  RawSpec coplanar;
  coplanar.ras.col(2) = coplanar.ras.col(0) + coplanar.ras.col(1);
  write_raw(path("coplanar.nii"), coplanar);
  expect_error([&] { read_nifti(path("coplanar.nii")); }, path("coplanar.nii"), "singular");
}

TEST_F(NiftiIo, ScalarAndVectorReadersRefuseEachOther) {
  const ImageVolume grid = oblique_grid();
  write_nifti_displacement(path("u.nii.gz"), grid, sample_displacement(grid));
  expect_error([&] { read_nifti(path("u.nii.gz")); }, path("u.nii.gz"), "3-D scalar");
  write_nifti(path("ct.nii.gz"), oblique_volume(NiftiType::Int16), NiftiType::Int16);
  std::vector<float> u;
  expect_error([&] { read_nifti_displacement(path("ct.nii.gz"), u); }, path("ct.nii.gz"),
               "displacement field");
}

TEST_F(NiftiIo, WriteErrorsLeaveNoFile) {
  ImageVolume image = oblique_volume(NiftiType::Int16);
  expect_error([&] { write_nifti(path("x.nrrd"), image, NiftiType::Int16); }, path("x.nrrd"),
               "extension");
  image.values[7] = 40000.0f;
  expect_error([&] { write_nifti(path("big.nii"), image, NiftiType::Int16); }, path("big.nii"),
               "voxel (2, 1, 0)");
  image.values[7] = -1.0f;
  expect_error([&] { write_nifti(path("neg.nii"), image, NiftiType::UInt8); }, path("neg.nii"),
               "does not fit");
  image.values[7] = std::nanf("");
  expect_error([&] { write_nifti(path("nan.nii"), image, NiftiType::Int16); }, path("nan.nii"),
               "does not fit");
  image.values.pop_back();
  expect_error([&] { write_nifti(path("short.nii"), image, NiftiType::Float32); },
               path("short.nii"), "values for");
  std::vector<float> u(5);
  expect_error([&] { write_nifti_displacement(path("u.nii"), image, u); }, path("u.nii"),
               "3 per voxel");
  const std::string nowhere = path("no/such/folder/x.nii");
  expect_error(
      [&] { write_nifti(nowhere, oblique_volume(NiftiType::Float32), NiftiType::Float32); },
      nowhere, "cannot create");
  EXPECT_TRUE(fs::is_empty(dir_));
}

// ---- fuzzing regressions (tests/fuzz/regressions/, the fuzzer's flag byte removed) --------------

const fs::path kRegressions = fs::path(VOXBREAST_SOURCE_DIR) / "tests" / "fuzz" / "regressions";

std::vector<char> file_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  EXPECT_TRUE(in) << file;
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::string& file, const std::vector<char>& bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  ASSERT_TRUE(out) << file;
}

/// `bytes` as one gzip member, written through znzlib like any .nii.gz (`scratch` is reused).
std::vector<char> gzipped(const std::vector<char>& bytes, const std::string& scratch) {
  znzFile out = znzopen(scratch.c_str(), "wb", 1);
  EXPECT_FALSE(znz_isnull(out)) << scratch;
  if (znz_isnull(out)) return {};
  EXPECT_EQ(znzwrite(bytes.data(), 1, bytes.size(), out), bytes.size());
  EXPECT_EQ(znzclose(out), 0);
  std::vector<char> packed = file_bytes(scratch);
  fs::remove(scratch);
  return packed;
}

std::uint64_t peak_rss_bytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return std::uint64_t(usage.ru_maxrss) * 1024;  // Linux: kilobytes
}

/// For a read that must fail before reading what the header promises: bounds how much it raises
/// this process's peak resident memory.
class CheapFailure {
 public:
  CheapFailure() : peak_(peak_rss_bytes()) {}
  ~CheapFailure() { EXPECT_LT(peak_rss_bytes() - peak_, std::uint64_t(64) << 20); }
  CheapFailure(const CheapFailure&) = delete;
  CheapFailure& operator=(const CheapFailure&) = delete;

 private:
  std::uint64_t peak_;
};

/// nifti_clib 3.0.1 copied dim[0] + 1 entries of a NIfTI-2 dim[] into an 8-entry array (stack
/// corruption) and accepted dim[0] = 9: our header check refuses them first, .nii or .nii.gz.
TEST_F(NiftiIo, FuzzRegressionNifti2DimZeroOutOfRange) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"nifti2_dim0_stack_overflow.nii", "dim[0] = 2319282339843"},
      {"nifti2_dim0_768_stack_corruption.nii", "dim[0] = 768"},
      {"nifti2_dim0_huge_minimal.nii", "dim[0] = 1099511627776"},
      {"nifti2_dim0_768_minimal.nii", "dim[0] = 768"},
      {"nifti2_dim0_9.nii", "dim[0] = 9"}};
  for (const auto& [name, text] : cases) {
    const std::vector<char> bytes = file_bytes(kRegressions / name);
    const std::string plain = path(name), gzip = path(name + ".gz");
    write_bytes(plain, bytes);
    write_bytes(gzip, gzipped(bytes, path("scratch.gz")));
    for (const std::string& file : {plain, gzip}) {
      CheapFailure cheap;
      expect_error([&] { read_nifti(file); }, file, text);
      std::vector<float> u;
      expect_error([&] { read_nifti_displacement(file, u); }, file, text);
    }
  }
}

/// Big-endian files read like little-endian ones, and their header is checked in their order.
TEST_F(NiftiIo, ByteSwappedHeadersAreCheckedInTheirOwnOrder) {
  const auto swapped_file = [&](const std::string& name, bool nifti2, std::int64_t dim0) {
    RawSpec spec;
    spec.nifti_type = nifti2 ? NIFTI_FTYPE_NIFTI2_1 : NIFTI_FTYPE_NIFTI1_1;
    write_raw(path("native.nii"), spec);
    std::vector<char> bytes = file_bytes(path("native.nii"));
    const std::size_t header_size = nifti2 ? sizeof(nifti_2_header) : sizeof(nifti_1_header);
    if (nifti2) {
      nifti_2_header h;
      std::memcpy(&h, bytes.data(), sizeof h);
      h.dim[0] = dim0;
      swap_nifti_header(&h, 2);
      std::memcpy(bytes.data(), &h, sizeof h);
    } else {
      nifti_1_header h;
      std::memcpy(&h, bytes.data(), sizeof h);
      h.dim[0] = std::int16_t(dim0);
      swap_nifti_header(&h, 1);
      std::memcpy(bytes.data(), &h, sizeof h);
    }
    EXPECT_EQ(bytes[0], 0) << "sizeof_hdr not swapped";
    for (std::size_t at = header_size + 4; at + 1 < bytes.size(); at += 2)  // int16 voxels
      std::swap(bytes[at], bytes[at + 1]);
    const bool gzip = name.size() > 3 && name.compare(name.size() - 3, 3, ".gz") == 0;
    write_bytes(path(name), gzip ? gzipped(bytes, path("scratch.gz")) : bytes);
    return path(name);
  };
  for (const bool nifti2 : {false, true}) {
    for (const std::string name : {"swapped.nii", "swapped.nii.gz"}) {
      SCOPED_TRACE(std::string(nifti2 ? "NIfTI-2 " : "NIfTI-1 ") + name);
      const ImageVolume image = read_nifti(swapped_file(name, nifti2, 3));
      EXPECT_EQ(image.dims, (std::array<int, 3>{3, 4, 2}));
      ASSERT_EQ(image.values.size(), 24u);
      for (std::size_t v = 0; v < image.values.size(); ++v)
        EXPECT_EQ(image.values[v], float(raw_value(v))) << v;
      const std::string bad = swapped_file("bad_" + name, nifti2, 9);
      CheapFailure cheap;
      expect_error([&] { read_nifti(bad); }, bad, "dim[0] = 9");
    }
  }
}

/// A 360-byte header claiming 2306 x 254 x 6914 uint8 voxels made nifti_image_load allocate 4 GB.
/// Now the voxel count is capped, and the voxels a header claims must fit in the file: its size
/// for .nii, the deflate ratio and the gzip trailer for .nii.gz, before anything is allocated.
TEST_F(NiftiIo, FuzzRegressionTinyFileClaimingHugeImage) {
  const std::vector<char> bytes = file_bytes(kRegressions / "nifti1_4gb_claim.nii");
  ASSERT_EQ(bytes.size(), 360u);
  const std::string original = path("claim.nii");
  write_bytes(original, bytes);
  {
    CheapFailure cheap;
    expect_error([&] { read_nifti(original); }, original, "larger than 2147483648 voxels");
  }

  // Under the cap (2306 x 254 x 1000 = 585724000 bytes) and with a sane vox_offset: the size.
  nifti_1_header h;
  std::memcpy(&h, bytes.data(), sizeof h);
  h.dim[3] = 1000;
  h.vox_offset = 352.0f;
  std::vector<char> smaller = bytes;
  std::memcpy(smaller.data(), &h, sizeof h);
  const std::vector<char> packed = gzipped(smaller, path("scratch.gz"));
  // A gzip trailer claiming 4 GiB - 1 uncompressed bytes; 1 MiB of zeros after the header, so
  // that reading the header does not reach the trailer (zlib checks it at the end of the stream).
  std::vector<char> padded = smaller;
  padded.resize(padded.size() + (std::size_t(1) << 20), 0);
  std::vector<char> forged = gzipped(padded, path("scratch.gz"));
  std::fill(forged.end() - 4, forged.end(), char(0xff));
  const std::vector<std::pair<std::string, const std::vector<char>*>> files = {
      {"smaller.nii", &smaller}, {"smaller.nii.gz", &packed}, {"forged.nii.gz", &forged}};
  for (const auto& [name, content] : files) {
    write_bytes(path(name), *content);
    CheapFailure cheap;
    expect_error([&] { read_nifti(path(name)); }, path(name),
                 "voxel data missing or truncated: the header describes 585724000 bytes");
    std::vector<float> u;
    expect_error([&] { read_nifti_displacement(path(name), u); }, path(name), "585724000 bytes");
  }
}

/// 40 × 30 × 20 voxels counting 0, 1, ... 996 over and over: enough that gzip output is long.
ImageVolume counting_volume() {
  ImageVolume image = oblique_grid();
  image.dims = {40, 30, 20};
  image.values.resize(image.voxel_count());
  for (std::size_t v = 0; v < image.values.size(); ++v) image.values[v] = float(v % 997);
  return image;
}

/// The gzip trailer counts only the last member of a multi-member file: the check then counts the
/// decompressed stream instead, so such a file still reads, and a short one is still refused.
TEST_F(NiftiIo, MultiMemberGzipIsMeasuredByItsStream) {
  const ImageVolume image = counting_volume();
  write_nifti(path("plain.nii"), image, NiftiType::Float32);
  const std::vector<char> bytes = file_bytes(path("plain.nii"));
  const auto two_members = [&](std::size_t size) {
    const std::size_t half = size / 2;
    std::vector<char> out = gzipped({bytes.begin(), bytes.begin() + long(half)}, path("a.gz"));
    const std::vector<char> second =
        gzipped({bytes.begin() + long(half), bytes.begin() + long(size)}, path("b.gz"));
    out.insert(out.end(), second.begin(), second.end());
    return out;
  };
  write_bytes(path("multi.nii.gz"), two_members(bytes.size()));
  const ImageVolume read = read_nifti(path("multi.nii.gz"));
  EXPECT_EQ(read.dims, image.dims);
  EXPECT_EQ(read.values, image.values);

  write_bytes(path("short.nii.gz"), two_members(bytes.size() - 100));
  expect_error([&] { read_nifti(path("short.nii.gz")); }, path("short.nii.gz"), "truncated");
}

/// nifti_clib reads only the bytes a header asks for, so it never reached the gzip trailer where
/// zlib checks the CRC-32 and the length: a .nii.gz with corrupt voxels read as a valid image.
/// Every gzip file is now checked to its end before it is used.
TEST_F(NiftiIo, CorruptGzipStreamIsRefused) {
  const ImageVolume image = counting_volume();
  write_nifti(path("good.nii.gz"), image, NiftiType::Float32);
  const std::vector<char> good = file_bytes(path("good.nii.gz"));
  ASSERT_GT(good.size(), 1000u);
  EXPECT_EQ(read_nifti(path("good.nii.gz")).values, image.values);

  const auto flipped = [&](std::size_t at) {
    std::vector<char> bytes = good;
    bytes[at] = char(bytes[at] ^ 0x01);
    return bytes;
  };
  const std::vector<std::pair<std::string, std::vector<char>>> cases = {
      {"crc.nii.gz", flipped(good.size() - 8)},      // the CRC-32 in the trailer
      {"isize.nii.gz", flipped(good.size() - 2)},    // the length, said larger than it is
      {"middle.nii.gz", flipped(good.size() / 2)}};  // a bit inside the voxels' deflate data
  for (const auto& [name, bytes] : cases) {
    SCOPED_TRACE(name);
    write_bytes(path(name), bytes);
    // A length said larger than the data is caught by the voxel-size check before the trailer's:
    // refused as incomplete or corrupt either way.
    expect_error([&] { read_nifti(path(name)); }, path(name), "corrupt");
    std::vector<float> u;
    expect_error([&] { read_nifti_displacement(path(name), u); }, path(name), "corrupt");
  }
  std::vector<char> trailing = good;
  trailing.insert(trailing.end(), {'j', 'u', 'n', 'k'});
  write_bytes(path("trailing.nii.gz"), trailing);
  expect_error([&] { read_nifti(path("trailing.nii.gz")); }, path("trailing.nii.gz"), "corrupt gzip stream");
}

// ---- external check through nibabel ------------------------------------------------------------

TEST_F(NiftiIo, NibabelSeesOurScalarFile) {
  REQUIRE_NIBABEL();
  const ImageVolume image = oblique_volume(NiftiType::Int16);
  write_nifti(path("ct.nii.gz"), image, NiftiType::Int16);
  auto seen = parse_lines(run_python(dir_, kNibabelDump, path("ct.nii.gz") + " 0 0 0 4 3 2 1 2 1"));

  EXPECT_EQ(seen["shape"], (std::vector<double>{5, 4, 3}));
  EXPECT_EQ(seen["codes"], (std::vector<double>{1, 1}));    // sform, qform: scanner
  EXPECT_EQ(seen["xyzt_units"], (std::vector<double>{2}));  // mm
  EXPECT_EQ(seen["nifti2"], (std::vector<double>{0}));
  const Eigen::Matrix4d expected = ras_mm(image.affine_lps_m);
  expect_affine_near(as_matrix(seen["affine"]), expected, 1e-4);  // mm
  expect_affine_near(as_matrix(seen["qform"]), expected, 1e-4);   // rigid x spacing: qform exact
  const std::vector<double> voxels{std::round(value_for(NiftiType::Int16, 0, 0, 0)),
                                   std::round(value_for(NiftiType::Int16, 4, 3, 2)),
                                   std::round(value_for(NiftiType::Int16, 1, 2, 1))};
  EXPECT_EQ(seen["voxels"], voxels);
}

TEST_F(NiftiIo, NibabelSeesDisplacementAsDispvectInRasMillimetres) {
  REQUIRE_NIBABEL();
  const ImageVolume grid = oblique_grid();
  const std::vector<float> u = sample_displacement(grid);
  write_nifti_displacement(path("u.nii.gz"), grid, u);
  auto seen = parse_lines(run_python(dir_, kNibabelDump, path("u.nii.gz") + " 3 2 1"));

  EXPECT_EQ(seen["shape"], (std::vector<double>{5, 4, 3, 1, 3}));
  EXPECT_EQ(seen["intent"], (std::vector<double>{1006}));  // NIFTI_INTENT_DISPVECT
  EXPECT_EQ(seen["codes"], (std::vector<double>{1, 1}));
  expect_affine_near(as_matrix(seen["affine"]), ras_mm(grid.affine_lps_m), 1e-4);
  // data[3, 2, 1, 0, :] holds u at voxel (3, 2, 1): RAS components (x, y negated), mm.
  const std::size_t v = grid.linear_index(3, 2, 1);
  const std::vector<double>& ras = seen["voxels"];
  ASSERT_EQ(ras.size(), 3u);
  EXPECT_NEAR(ras[0], -1000.0 * u[3 * v + 0], 1e-4);
  EXPECT_NEAR(ras[1], -1000.0 * u[3 * v + 1], 1e-4);
  EXPECT_NEAR(ras[2], 1000.0 * u[3 * v + 2], 1e-4);
}

/// nibabel writes (its own header, no nifti_clib): int16 voxels, scl_slope 2, an oblique affine.
const char* const kNibabelWriteScalar = R"PY(
import sys
import nibabel as nib
import numpy as np
affine = np.array([float(a) for a in sys.argv[2:18]]).reshape(4, 4)
raw = (np.arange(60).reshape((5, 4, 3), order='F') * 3 - 20).astype(np.int16)
img = nib.Nifti1Image(raw, affine)
img.set_qform(affine, code=1)
img.set_sform(affine, code=1)
img.header.set_xyzt_units('mm')
img.header.set_slope_inter(2.0, -3.0)
nib.save(img, sys.argv[1])
)PY";

/// nibabel writes an ITK-style (ANTs) field: intent VECTOR, components in LPS mm.
const char* const kNibabelWriteItkVector = R"PY(
import sys
import nibabel as nib
import numpy as np
affine = np.diag([-2.0, -3.0, 4.0, 1.0])
field = np.zeros((2, 3, 4, 1, 3), dtype=np.float32)
for i in range(2):
    for j in range(3):
        for k in range(4):
            field[i, j, k, 0, :] = [i + 0.5, -j - 0.25, 0.125 * k]
img = nib.Nifti1Image(field, affine)
img.header.set_intent('vector')
img.header.set_xyzt_units('mm')
nib.save(img, sys.argv[1])
)PY";

std::string affine_args(const Eigen::Matrix4d& m) {
  std::ostringstream out;
  out.precision(17);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out << ' ' << m(r, c);
  return out.str();
}

TEST_F(NiftiIo, ReadsNibabelFileInLpsMetresWithScaling) {
  REQUIRE_NIBABEL();
  const Eigen::Matrix4d lps = oblique_grid().affine_lps_m;
  run_python(dir_, kNibabelWriteScalar, path("nib.nii.gz") + affine_args(ras_mm(lps)));
  const ImageVolume image = read_nifti(path("nib.nii.gz"));
  EXPECT_EQ(image.dims, (std::array<int, 3>{5, 4, 3}));
  expect_affine_near(image.affine_lps_m, lps, kAffineTolerance_m);
  ASSERT_EQ(image.values.size(), 60u);
  for (std::size_t v = 0; v < image.values.size(); ++v)
    EXPECT_EQ(image.values[v], 2.0f * float(3 * int(v) - 20) - 3.0f) << v;
}

TEST_F(NiftiIo, ReadsItkStyleVectorFieldAsLps) {
  REQUIRE_NIBABEL();
  run_python(dir_, kNibabelWriteItkVector, path("warp.nii.gz"));
  std::vector<float> u;
  const ImageVolume grid = read_nifti_displacement(path("warp.nii.gz"), u);
  EXPECT_EQ(grid.dims, (std::array<int, 3>{2, 3, 4}));
  const std::size_t v = grid.linear_index(1, 2, 3);
  EXPECT_FLOAT_EQ(u[3 * v + 0], 1.5e-3f);  // VECTOR: already LPS, only mm -> m
  EXPECT_FLOAT_EQ(u[3 * v + 1], -2.25e-3f);
  EXPECT_FLOAT_EQ(u[3 * v + 2], 0.375e-3f);
  expect_affine_near(grid.affine_lps_m, Eigen::Vector4d(2e-3, 3e-3, 4e-3, 1).asDiagonal(), 1e-12);
}

}  // namespace
}  // namespace vb
