#include "io/dicom_pixels.hpp"

#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcpixel.h>
#include <dcmtk/dcmdata/dcpixseq.h>
#include <dcmtk/dcmdata/dcpxitem.h>
#include <dcmtk/dcmdata/dcxfer.h>

#include <filesystem>
#include <optional>

#include "engine/error.hpp"
#include "io/dicom_attributes.hpp"
#include "io/dicom_deflate.hpp"

namespace fs = std::filesystem;

namespace vb::dicom {
namespace {

/// Compressed (encapsulated) pixel data may decode to at most kMaxCompressionRatio times the
/// file's size, plus kCompressedAllowanceBytes for any file. Real CT slices compress far less;
/// JPEG-LS can beat 1024:1 only on large uniform areas, and the allowance covers those for slices
/// up to 4096 × 4096 at 16 bits. Without this bound a file of a few hundred bytes could make
/// DCMTK's decoder allocate gigabytes.
constexpr std::uint64_t kMaxCompressionRatio = 1024;
constexpr std::uint64_t kCompressedAllowanceBytes = std::uint64_t(32) << 20;
/// A deflated dataset (Deflated Explicit VR Little Endian) inflates at most 1032:1.
constexpr std::uint64_t kMaxDeflateRatio = 1032;

/// The Image Pixel attributes this reader supports; nothing is decoded or allocated yet.
PixelLayout check_pixel_layout(DcmDataset& data, int rows, int columns, const std::string& path) {
  require(get_uint16(data, DCM_Rows, 0) == rows && get_uint16(data, DCM_Columns, 0) == columns,
          "Rows/Columns changed while the series was read", path);
  const int samples = get_uint16(data, DCM_SamplesPerPixel, 1);
  const std::string photometric = get_text(data, DCM_PhotometricInterpretation);
  PixelLayout layout;
  layout.bits_allocated = get_uint16(data, DCM_BitsAllocated, 0);
  layout.bits_stored = get_uint16(data, DCM_BitsStored, Uint16(layout.bits_allocated));
  const int high_bit = get_uint16(data, DCM_HighBit, Uint16(layout.bits_stored - 1));
  layout.is_signed = get_uint16(data, DCM_PixelRepresentation, 0) == 1;
  const double frames = get_number(data, DCM_NumberOfFrames).value_or(1);
  require(samples == 1,
          "only greyscale images (SamplesPerPixel 1) are supported, not SamplesPerPixel " +
              std::to_string(samples),
          path);
  require(photometric == "MONOCHROME1" || photometric == "MONOCHROME2",
          "only greyscale images (PhotometricInterpretation MONOCHROME1 or MONOCHROME2) are "
          "supported, not '" +
              photometric + "'",
          path);
  require(frames == 1, "multi-frame images are not supported", path,
          "convert the series to one file per slice");
  require((layout.bits_allocated == 8 || layout.bits_allocated == 16) && layout.bits_stored >= 1 &&
              layout.bits_stored <= layout.bits_allocated && high_bit == layout.bits_stored - 1,
          "unsupported pixel layout (BitsAllocated " + std::to_string(layout.bits_allocated) +
              ", BitsStored " + std::to_string(layout.bits_stored) + ", HighBit " +
              std::to_string(high_bit) + ")",
          path);
  layout.pixels = std::uint64_t(rows) * std::uint64_t(columns);
  layout.bytes = layout.pixels * std::uint64_t(layout.bits_allocated / 8);
  return layout;
}

std::string pixels_text(int rows, int columns, const PixelLayout& layout) {
  return std::to_string(columns) + " x " + std::to_string(rows) + " pixels of " +
         std::to_string(layout.bits_allocated) + " bits (" + std::to_string(layout.bytes) +
         " bytes)";
}

/// Rows, columns and components of a JPEG or JPEG-LS stream, from its frame header (SOFn, or
/// SOF55 for JPEG-LS); nullopt when none is found in `bytes` (not JPEG, or cut).
struct FrameHeader {
  int rows = 0, columns = 0, components = 0;
};

std::optional<FrameHeader> jpeg_frame_header(const Uint8* bytes, std::size_t size) {
  if (size < 4 || bytes[0] != 0xFF || bytes[1] != 0xD8) return std::nullopt;  // SOI
  std::size_t at = 2;
  while (at + 4 <= size) {
    if (bytes[at] != 0xFF) return std::nullopt;
    const Uint8 marker = bytes[at + 1];
    if (marker == 0xFF) {  // fill byte
      ++at;
      continue;
    }
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD8)) {  // TEM, RSTn, SOI: no length
      at += 2;
      continue;
    }
    if (marker == 0xD9 || marker == 0xDA) return std::nullopt;  // EOI or SOS before a frame
    const bool frame = (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 &&
                        marker != 0xCC) ||
                       marker == 0xF7;
    if (frame) {
      if (at + 10 > size) return std::nullopt;
      // FF Cn, Lf (2), P (1), Y (2), X (2), Nf (1)
      return FrameHeader{bytes[at + 5] << 8 | bytes[at + 6], bytes[at + 7] << 8 | bytes[at + 8],
                         bytes[at + 9]};
    }
    at += 2 + (std::size_t(bytes[at + 2]) << 8 | bytes[at + 3]);
  }
  return std::nullopt;
}

/// DCMTK's decoders size their output from Rows and Columns and decode whatever the stream holds
/// into it: a JPEG or JPEG-LS frame of another size would be read as garbage without an error.
/// So the first fragment's frame header must agree with the dataset (a height of 0, "defined
/// later by a DNL marker", is left to the decoder).
void check_compressed_frame(DcmElement& pixel_data, const PixelLayout& layout, int rows,
                            int columns, const std::string& path) {
  auto* pixels = dynamic_cast<DcmPixelData*>(&pixel_data);
  E_TransferSyntax syntax = EXS_Unknown;
  const DcmRepresentationParameter* parameter = nullptr;
  DcmPixelSequence* sequence = nullptr;
  DcmPixelItem* fragment = nullptr;
  Uint8* bytes = nullptr;
  if (pixels) pixels->getOriginalRepresentationKey(syntax, parameter);
  const bool found = pixels &&
                     pixels->getEncapsulatedRepresentation(syntax, parameter, sequence).good() &&
                     sequence && sequence->getItem(fragment, 1).good() && fragment &&
                     fragment->getUint8Array(bytes).good() && bytes;
  require(found, "no compressed pixel data fragment", path, kCorruptFileHint);
  const std::optional<FrameHeader> frame = jpeg_frame_header(bytes, fragment->getLength());
  if (!frame) return;  // not JPEG (RLE has no frame size): the decoded length is checked later
  require(frame->columns == columns && (frame->rows == rows || frame->rows == 0) &&
              frame->components == 1,
          "the compressed frame is " + std::to_string(frame->columns) + " x " +
              std::to_string(frame->rows) + " pixels with " + std::to_string(frame->components) +
              " component(s), the header says " + pixels_text(rows, columns, layout),
          path, kCorruptFileHint);
}

/// The pixel data's size against the layout, from its length field (native) or the file size
/// (compressed): the value itself is not loaded (DCMTK loads large values on first access).
void check_pixel_data_size(DcmDataset& data, const PixelLayout& layout, int rows, int columns,
                           const std::string& path) {
  DcmElement* pixel_data = nullptr;
  require(data.findAndGetElement(DCM_PixelData, pixel_data).good() && pixel_data != nullptr,
          "no pixel data", path, kCorruptFileHint);
  std::error_code ec;
  const std::uint64_t file_size = fs::file_size(path, ec);
  require(!ec, "cannot read the file size: " + ec.message(), path);
  const DcmXfer syntax(data.getOriginalXfer());
  if (syntax.isEncapsulated()) {
    require(layout.bytes <= kCompressedAllowanceBytes + kMaxCompressionRatio * file_size,
            "compressed pixel data in a file of " + std::to_string(file_size) +
                " bytes cannot hold " + pixels_text(rows, columns, layout),
            path, kCorruptFileHint);
    check_compressed_frame(*pixel_data, layout, rows, columns, path);
    return;
  }
  const std::uint64_t length = pixel_data->getLengthField();
  require(length >= layout.bytes,
          "pixel data too short: " + std::to_string(length) + " bytes for " +
              pixels_text(rows, columns, layout),
          path, "the file may be truncated");
  const bool deflated = syntax.getStreamCompression() != ESC_none;
  require(length / (deflated ? kMaxDeflateRatio : 1) <= file_size,
          "pixel data of " + std::to_string(length) + " bytes in a file of " +
              std::to_string(file_size) + " bytes",
          path, kCorruptFileHint);
}

}  // namespace

std::unique_ptr<DcmFileFormat> load_slice(const std::string& path, int rows, int columns,
                                          PixelLayout& layout) {
  check_deflated_dataset(path);
  auto file = std::make_unique<DcmFileFormat>();
  const OFCondition status = file->loadFile(path.c_str());
  require(status.good(), std::string("cannot read DICOM file: ") + status.text(), path,
          kCorruptFileHint);
  DcmDataset& data = *file->getDataset();
  layout = check_pixel_layout(data, rows, columns, path);
  check_pixel_data_size(data, layout, rows, columns, path);
  return file;
}

namespace {

/// Brings encapsulated (compressed) pixel data to native form with the registered decoders;
/// true when there was something to decode.
bool decompress(DcmDataset& data, const std::string& path) {
  const DcmXfer syntax(data.getOriginalXfer());
  if (!syntax.isEncapsulated()) return false;
  const bool decoded = data.chooseRepresentation(EXS_LittleEndianExplicit, nullptr).good() &&
                       data.canWriteXfer(EXS_LittleEndianExplicit);
  require(decoded,
          std::string("cannot decode transfer syntax ") + syntax.getXferName() + " (" +
              syntax.getXferID() + ")",
          path,
          "supported: uncompressed, deflated, JPEG baseline/extended/lossless, JPEG-LS, RLE; "
          "convert the series first (e.g. gdcmconv --raw)");
  return true;
}

/// Stored value of a pixel: the low `bits_stored` bits, two's complement when signed.
std::int64_t stored_value(std::uint32_t raw, int bits_stored, bool is_signed) {
  const std::uint32_t mask = (std::uint32_t(1) << bits_stored) - 1;  // bits_stored ≤ 16
  const std::int64_t value = raw & mask;
  const bool negative = is_signed && (value >> (bits_stored - 1)) != 0;
  return negative ? value - (std::int64_t(1) << bits_stored) : value;
}

/// The native pixel array: `count` values of 8 or 16 bits (no copy).
template <class T>
const T* native_pixels(DcmDataset& data, unsigned long& count, const std::string& path) {
  const T* values = nullptr;
  OFCondition status;
  if constexpr (sizeof(T) == 2)
    status = data.findAndGetUint16Array(DCM_PixelData, values, &count);
  else
    status = data.findAndGetUint8Array(DCM_PixelData, values, &count);
  require(status.good() && values != nullptr && count > 0, "no readable pixel data", path,
          kCorruptFileHint);
  return values;
}

}  // namespace

void read_slice_pixels(const std::string& path, int rows, int columns, float* out) {
  PixelLayout layout;
  const std::unique_ptr<DcmFileFormat> file = load_slice(path, rows, columns, layout);
  DcmDataset& data = *file->getDataset();
  const bool decoded = decompress(data, path);
  const double slope = get_number(data, DCM_RescaleSlope).value_or(1.0);
  const double intercept = get_number(data, DCM_RescaleIntercept).value_or(0.0);

  const auto convert = [&](auto tag) {
    using T = decltype(tag);
    unsigned long count = 0;
    const T* raw = native_pixels<T>(data, count, path);
    // A decoder's output must be exactly one frame (8 bits: padded to even length); native data
    // was checked against its length field already.
    const std::uint64_t pixels = layout.pixels;
    const bool exact =
        count == pixels || (sizeof(T) == 1 && pixels % 2 == 1 && count == pixels + 1);
    require(decoded ? exact : count >= pixels,
            "pixel data holds " + std::to_string(count) + " values for " +
                pixels_text(rows, columns, layout),
            path, kCorruptFileHint);
    for (std::uint64_t n = 0; n < pixels; ++n)
      out[n] = float(double(stored_value(raw[n], layout.bits_stored, layout.is_signed)) * slope +
                     intercept);
  };
  if (layout.bits_allocated == 16)
    convert(Uint16{});
  else
    convert(Uint8{});
}

}  // namespace vb::dicom
