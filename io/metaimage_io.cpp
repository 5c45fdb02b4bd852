#include "io/metaimage_io.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "engine/error.hpp"
#include "io/atomic_file.hpp"

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
std::string header(const ImageVolume& grid, std::size_t compressed_bytes, const std::string& path) {
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
         "CompressedData = True\nCompressedDataSize = " + std::to_string(compressed_bytes) +
         "\nTransformMatrix = " + numbers_text(direction, 9) + "\nOffset = " + numbers_text(origin, 3) +
         "\nCenterOfRotation = 0 0 0\nElementSpacing = " + numbers_text(spacing, 3) +
         "\nDimSize = " + numbers_text(dims, 3) +
         "\nElementNumberOfChannels = 3\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n";
}

/// The voxels as LPS mm float32 (little-endian), deflated (zlib stream) chunk by chunk.
std::string compressed_mm(const ImageVolume& grid, const std::vector<float>& u_m, const std::string& path) {
  z_stream z{};
  require(deflateInit(&z, Z_BEST_SPEED) == Z_OK, "cannot start zlib compression", path);
  std::string out;
  std::vector<float> chunk;
  std::vector<unsigned char> buffer(1 << 20);
  const std::size_t n = grid.voxel_count(), per_chunk = 1 << 16;
  const auto drain = [&](int flush) {
    do {
      z.next_out = buffer.data();
      z.avail_out = unsigned(buffer.size());
      const int status = deflate(&z, flush);
      if (status == Z_STREAM_ERROR) {
        deflateEnd(&z);
        throw Error("zlib compression failed", path);
      }
      out.append(reinterpret_cast<const char*>(buffer.data()), buffer.size() - z.avail_out);
    } while (z.avail_out == 0);
  };
  for (std::size_t first = 0; first < n; first += per_chunk) {
    const std::size_t count = std::min(per_chunk, n - first);
    chunk.resize(kComponents * count);
    for (std::size_t v = 0; v < kComponents * count; ++v) {
      const float u = u_m[kComponents * first + v];
      if (!std::isfinite(u)) {
        deflateEnd(&z);
        const std::size_t voxel = first + v / kComponents, nx = std::size_t(grid.dims[0]), ny = std::size_t(grid.dims[1]);
        throw Error("displacement is not finite at voxel (" + std::to_string(voxel % nx) + ", " +
                        std::to_string(voxel / nx % ny) + ", " + std::to_string(voxel / (nx * ny)) + ")",
                    path);
      }
      chunk[v] = float(double(u) * 1e3);
    }
    z.next_in = reinterpret_cast<unsigned char*>(chunk.data());
    z.avail_in = unsigned(chunk.size() * sizeof(float));
    drain(Z_NO_FLUSH);
  }
  z.next_in = nullptr;
  z.avail_in = 0;
  drain(Z_FINISH);
  deflateEnd(&z);
  return out;
}

}  // namespace

void write_metaimage_displacement(const std::string& path, const ImageVolume& grid,
                                  const std::vector<float>& displacement_lps_m) {
  require(path.size() > 4 && path.compare(path.size() - 4, 4, ".mha") == 0,
          "a MetaImage displacement field is written as one '.mha' file", path);
  require(displacement_lps_m.size() == kComponents * grid.voxel_count(),
          "displacement has " + std::to_string(displacement_lps_m.size()) + " floats for " +
              std::to_string(grid.voxel_count()) + " voxels (3 per voxel expected)",
          path);
  const std::string data = compressed_mm(grid, displacement_lps_m, path);
  const std::string text = header(grid, data.size(), path);
  AtomicOutput output(path);
  {
    std::ofstream file(output.temp_path(), std::ios::binary);
    file.write(text.data(), std::streamsize(text.size()));
    file.write(data.data(), std::streamsize(data.size()));
    file.close();
    require(bool(file), "cannot write the file", path);
  }
  output.commit();
}

}  // namespace vb
