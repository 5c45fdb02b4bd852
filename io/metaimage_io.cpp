#include "io/metaimage_io.hpp"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "engine/error.hpp"
#include "io/atomic_file.hpp"
#include "io/gzip_blocks.hpp"

namespace vb {
namespace {

constexpr std::size_t kComponents = 3;

/// Round-trip text of a double ("%.17g" without trailing noise where shorter text is exact).
std::string number_text(double value) {
  if (std::abs(value) < 1e-15) value = 0;  // rotations leave 1e-17-style noise
  char text[40];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, value);
    if (std::strtod(text, nullptr) == value) break;
  }
  return text;
}

std::string numbers_text(const double* values, int count) {
  std::string text;
  for (int n = 0; n < count; ++n) text += (n ? " " : "") + number_text(values[n]);
  return text;
}

/// MetaImage header for a 3-channel float image on `grid`'s voxels; ITK's order of keys, ending
/// with ElementDataFile (the data follow it).
std::string header(const ImageVolume& grid, const std::string& compressed_bytes, const std::string& path) {
  const Eigen::Matrix3d axes_mm = grid.affine_lps_m.topLeftCorner<3, 3>() * 1e3;
  double spacing[3], origin[3], direction[9];
  for (int a = 0; a < 3; ++a) {
    spacing[a] = axes_mm.col(a).norm();
    require(spacing[a] > 0, "the grid's voxel axis " + std::to_string(a) + " has zero length", path);
    origin[a] = grid.affine_lps_m(a, 3) * 1e3;
  }
  const Eigen::Matrix3d unit = axes_mm * Eigen::Vector3d(spacing[0], spacing[1], spacing[2]).cwiseInverse().asDiagonal();
  require((unit.transpose() * unit - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-4,
          "the grid's affine is sheared (voxel axes not perpendicular)", path,
          "an ITK image holds a rotation and a spacing only; resample the CT first");
  // TransformMatrix lists each voxel axis's direction in turn (ITK: direction column a).
  for (int a = 0; a < 3; ++a)
    for (int r = 0; r < 3; ++r) direction[3 * a + r] = unit(r, a);
  const double dims[3] = {double(grid.dims[0]), double(grid.dims[1]), double(grid.dims[2])};
  return "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
         "CompressedData = True\nCompressedDataSize = " + compressed_bytes +
         "\nTransformMatrix = " + numbers_text(direction, 9) + "\nOffset = " + numbers_text(origin, 3) +
         "\nCenterOfRotation = 0 0 0\nElementSpacing = " + numbers_text(spacing, 3) +
         "\nDimSize = " + numbers_text(dims, 3) +
         "\nElementNumberOfChannels = 3\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n";
}

/// CompressedDataSize's text, padded with spaces to a fixed width so that the header can be
/// written before the data and its size filled in after them.
std::string size_field(std::size_t bytes) {
  std::string text = std::to_string(bytes);
  text.resize(20, ' ');
  return text;
}

}  // namespace

void write_metaimage_displacement(const std::string& path, const ImageVolume& grid,
                                  const std::vector<float>& displacement_lps_m,
                                  const std::function<void(double)>& progress) {
  require(path.size() > 4 && path.compare(path.size() - 4, 4, ".mha") == 0,
          "a MetaImage displacement field is written as one '.mha' file", path);
  require(displacement_lps_m.size() == kComponents * grid.voxel_count(),
          "displacement has " + std::to_string(displacement_lps_m.size()) + " floats for " +
              std::to_string(grid.voxel_count()) + " voxels (3 per voxel expected)",
          path);
  // The voxels as LPS mm float32 (little-endian), one zlib stream deflated in blocks on all cores.
  const std::string placeholder = header(grid, size_field(0), path);
  AtomicOutput output(path);
  std::FILE* file = std::fopen(output.temp_path().c_str(), "wb");
  require(file != nullptr, "cannot create file", path, "check the folder and its permissions");
  const std::size_t n = grid.voxel_count(), nx = std::size_t(grid.dims[0]), ny = std::size_t(grid.dims[1]);
  bool ok = false;
  try {
    ok = std::fwrite(placeholder.data(), 1, placeholder.size(), file) == placeholder.size() &&
         write_blocks(file, "", sizeof(float) * kComponents * n, [&](std::size_t offset, unsigned char* bytes, std::size_t size) {
           static_assert(std::endian::native == std::endian::little, "MetaImage data are written little-endian");
           float* out = reinterpret_cast<float*>(bytes);  // blocks split between floats (sizes are multiples of 4)
           for (std::size_t f = offset / sizeof(float), end = f + size / sizeof(float); f < end; ++f) {
             const float u = displacement_lps_m[f];
             if (!std::isfinite(u)) {
               const std::size_t voxel = f / kComponents;
               throw Error("displacement is not finite at voxel (" + std::to_string(voxel % nx) + ", " +
                               std::to_string(voxel / nx % ny) + ", " + std::to_string(voxel / (nx * ny)) + ")",
                           path);
             }
             *out++ = float(double(u) * 1e3);
           }
         }, BlockCompression::Zlib, Z_BEST_SPEED, progress);
    const long end = std::ftell(file);
    const std::string text = header(grid, size_field(std::size_t(end) - placeholder.size()), path);
    ok = ok && end > 0 && text.size() == placeholder.size() && std::fseek(file, 0, SEEK_SET) == 0 &&
         std::fwrite(text.data(), 1, text.size(), file) == text.size();
  } catch (...) {
    std::fclose(file);
    throw;
  }
  ok = std::fclose(file) == 0 && ok;
  require(ok, "cannot write the file", path, "check free disk space");
  output.commit();
}

}  // namespace vb
