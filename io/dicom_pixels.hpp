#pragma once
/// One CT slice's pixels, checked before memory is committed to them (internal to io/).
#include <dcmtk/config/osconfig.h>  // DCMTK: must come before its other headers
#include <dcmtk/dcmdata/dcfilefo.h>

#include <cstdint>
#include <memory>
#include <string>

namespace vb::dicom {

// A slice's pixel attributes and the size of its pixel data are checked before any memory is
// committed to its pixels: before the volume is allocated (Rows × Columns × slices floats) and
// before DCMTK decodes compressed data, since its decoders allocate their output from Rows,
// Columns, SamplesPerPixel and BitsAllocated before they look at the compressed stream.

/// Largest volume read: 2^31 voxels (8 GiB of float values).
constexpr std::uint64_t kMaxVoxels = std::uint64_t(1) << 31;

/// How one slice's pixels are stored: one frame, one sample per pixel.
struct PixelLayout {
  int bits_allocated = 0, bits_stored = 0;
  bool is_signed = false;
  std::uint64_t pixels = 0;  ///< Rows × Columns
  std::uint64_t bytes = 0;   ///< pixels × BitsAllocated / 8
};

/// A slice file (values of large elements are loaded on access) whose pixel attributes and pixel
/// data size have been checked.
std::unique_ptr<DcmFileFormat> load_slice(const std::string& path, int rows, int columns,
                                          PixelLayout& layout);

/// Decodes one slice's pixels into `out` (rows × columns, column index fastest) in rescaled units.
void read_slice_pixels(const std::string& path, int rows, int columns, float* out);

}  // namespace vb::dicom
