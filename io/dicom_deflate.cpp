#include "io/dicom_deflate.hpp"

#include <dcmtk/config/osconfig.h>  // DCMTK: must come before its other headers
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcmetinf.h>
#include <dcmtk/dcmdata/dcxfer.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <optional>
#include <vector>

#include "io/dicom_attributes.hpp"

namespace vb::dicom {
namespace {

/// Reads a raw deflate stream (RFC 1951, what DCMTK expects by default) from a file, inflating
/// through a fixed buffer: nothing is kept, bytes are copied out or skipped.
class InflatingReader {
 public:
  InflatingReader(std::ifstream& in) : in_(in) { ok_ = inflateInit2(&z_, -MAX_WBITS) == Z_OK; }
  ~InflatingReader() { inflateEnd(&z_); }
  InflatingReader(const InflatingReader&) = delete;
  InflatingReader& operator=(const InflatingReader&) = delete;

  /// Up to `n` bytes into `out` (skipped when null); fewer when the stream ends or is corrupt.
  std::uint64_t read(unsigned char* out, std::uint64_t n) {
    std::uint64_t done = 0;
    while (done < n && (next_ < end_ || refill())) {
      const std::size_t take = std::size_t(std::min<std::uint64_t>(n - done, end_ - next_));
      if (out) std::memcpy(out + done, output_.data() + next_, take);
      next_ += take;
      done += take;
    }
    position_ += done;
    return done;
  }
  std::uint64_t position() const { return position_; }
  /// Whether the deflate stream ended with its final block and inflated without an error: a
  /// stream cut off or corrupted between two attributes reads like a shorter dataset otherwise.
  bool complete() const { return ok_ && stream_end_; }

 private:
  bool refill() {
    next_ = end_ = 0;
    z_.next_out = output_.data();
    z_.avail_out = uInt(output_.size());
    while (ok_ && !ended_ && z_.avail_out == output_.size()) {
      if (z_.avail_in == 0) {
        in_.read(reinterpret_cast<char*>(input_.data()), std::streamsize(input_.size()));
        z_.next_in = input_.data();
        z_.avail_in = uInt(in_.gcount());
        if (z_.avail_in == 0) ended_ = true;  // the file ends inside the stream
      }
      if (ended_) break;
      const int status = inflate(&z_, Z_NO_FLUSH);
      if (status == Z_STREAM_END) ended_ = stream_end_ = true;
      else if (status != Z_OK) ok_ = false;
    }
    end_ = output_.size() - z_.avail_out;
    return end_ > 0;
  }

  std::ifstream& in_;
  z_stream z_{};
  bool ok_ = false, ended_ = false, stream_end_ = false;
  std::array<unsigned char, 16384> input_{}, output_{};
  std::size_t next_ = 0, end_ = 0;
  std::uint64_t position_ = 0;
};

/// Walks a deflated dataset's attributes (explicit VR little endian; implicit inside a UN value of
/// undefined length, as DCMTK reads those), checking each length against the bytes there are and
/// against the item or sequence holding it. Values are skipped, not read.
class DeflatedDatasetWalk {
 public:
  explicit DeflatedDatasetWalk(InflatingReader& in) : in_(in) {}
  bool dataset() { return elements(kUnbounded, true, Context::top, 0); }

 private:
  static constexpr std::uint64_t kUnbounded = ~std::uint64_t(0);
  static constexpr std::uint32_t kUndefinedLength = 0xFFFFFFFF;
  static constexpr int kMaxNesting = 64;
  enum class Context { top, defined_item, undefined_item };

  bool bytes(unsigned char* out, std::uint64_t n, std::uint64_t end) {
    return in_.position() + n <= end && in_.read(out, n) == n;
  }
  bool number(std::uint32_t& value, int size, std::uint64_t end) {
    unsigned char b[4] = {0, 0, 0, 0};
    if (!bytes(b, std::uint64_t(size), end)) return false;
    value = std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 | std::uint32_t(b[2]) << 16 |
            std::uint32_t(b[3]) << 24;
    return true;
  }

  /// Attributes until `end` (a defined length), an item delimiter (undefined-length item) or,
  /// at the top, the end of the stream between two attributes.
  bool elements(std::uint64_t end, bool explicit_vr, Context context, int depth) {
    if (depth > kMaxNesting) return false;
    while (true) {
      if (context == Context::defined_item && in_.position() == end) return true;
      unsigned char tag[4];
      const std::uint64_t got = in_.position() + 4 <= end ? in_.read(tag, 4) : 0;
      if (got == 0 && context == Context::top) return true;
      if (got < 4) return false;
      const unsigned group = tag[0] | tag[1] << 8, element = tag[2] | tag[3] << 8;
      std::uint32_t length = 0;
      if (group == 0xFFFE) {  // only an item delimiter belongs here
        return element == 0xE00D && context == Context::undefined_item && number(length, 4, end);
      }
      char vr[2] = {0, 0};
      if (explicit_vr) {
        if (!bytes(reinterpret_cast<unsigned char*>(vr), 2, end)) return false;
        const std::string name(vr, 2);
        const bool long_length = name == "OB" || name == "OD" || name == "OF" || name == "OL" ||
                                 name == "OV" || name == "OW" || name == "SQ" || name == "SV" ||
                                 name == "UC" || name == "UN" || name == "UR" || name == "UT" ||
                                 name == "UV";
        std::uint32_t reserved = 0;
        if (long_length ? !(number(reserved, 2, end) && number(length, 4, end))
                        : !number(length, 2, end))
          return false;
      } else if (!number(length, 4, end)) {
        return false;
      }
      const std::string name(vr, 2);
      const bool pixel_data = group == 0x7FE0 && element == 0x0010;
      if (length == kUndefinedLength) {
        if (!explicit_vr || name == "SQ" || name == "UN") {
          // a sequence; in an UN value its items are implicit VR (CP-246)
          if (!sequence(end, explicit_vr && name == "SQ", pixel_data && !explicit_vr, depth + 1))
            return false;
        } else if (pixel_data && (name == "OB" || name == "OW")) {
          if (!sequence(end, true, true, depth + 1)) return false;  // compressed fragments
        } else {
          return false;
        }
      } else if (explicit_vr && name == "SQ") {
        const std::uint64_t sequence_end = in_.position() + length;
        if (sequence_end > end || !defined_sequence(sequence_end, depth + 1)) return false;
      } else if (!bytes(nullptr, length, end)) {
        return false;
      }
    }
  }

  /// Items of a sequence of undefined length, up to its delimiter.
  bool sequence(std::uint64_t end, bool explicit_vr, bool fragments, int depth) {
    if (depth > kMaxNesting) return false;
    while (true) {
      std::uint32_t tag = 0, length = 0;
      if (!number(tag, 4, end) || !number(length, 4, end)) return false;
      if (tag == 0xE0DDFFFE) return true;  // sequence delimiter (FFFE,E0DD)
      if (tag != 0xE000FFFE || !item(end, length, explicit_vr, fragments, depth)) return false;
    }
  }

  /// Items of an explicit VR sequence of defined length, up to `end`.
  bool defined_sequence(std::uint64_t end, int depth) {
    while (in_.position() < end) {
      std::uint32_t tag = 0, length = 0;
      if (!number(tag, 4, end) || !number(length, 4, end)) return false;
      if (tag == 0xE0DDFFFE) return in_.position() == end;
      if (tag != 0xE000FFFE || !item(end, length, true, false, depth)) return false;
    }
    return true;
  }

  bool item(std::uint64_t end, std::uint32_t length, bool explicit_vr, bool fragment, int depth) {
    if (length == kUndefinedLength)
      return !fragment && elements(end, explicit_vr, Context::undefined_item, depth + 1);
    const std::uint64_t item_end = in_.position() + length;
    if (item_end > end) return false;
    if (fragment) return bytes(nullptr, length, end);
    return elements(item_end, explicit_vr, Context::defined_item, depth + 1);
  }

  InflatingReader& in_;
};

/// The transfer syntax in a Part 10 file's meta header (group 0002, explicit VR little endian
/// after "DICM" at byte 128) and the offset where the dataset starts. nullopt when the meta header
/// cannot be walked, or when its group length (0002,0000) disagrees with the walk (DCMTK ends the
/// header by the group length: the two must agree on where the deflated stream starts).
struct MetaHeader {
  std::string transfer_syntax;
  std::uint64_t dataset_offset = 0;
};

std::optional<MetaHeader> walk_meta_header(std::ifstream& in) {
  std::array<char, 132> head{};
  if (!in.read(head.data(), head.size()) || std::string(&head[128], 4) != "DICM")
    return std::nullopt;
  MetaHeader meta;
  std::optional<std::uint64_t> group_end;
  std::uint64_t at = 132;
  while (true) {
    unsigned char element[12] = {};
    in.read(reinterpret_cast<char*>(element), 8);
    if (in.gcount() < 8 || (element[0] | element[1] << 8) != 0x0002) break;
    const unsigned number = element[2] | element[3] << 8;
    const std::string vr(reinterpret_cast<char*>(element + 4), 2);
    std::uint64_t length = element[6] | element[7] << 8, header = 8;
    if (vr == "OB" || vr == "OW" || vr == "UN" || vr == "SQ" || vr == "UT" || vr == "UC" ||
        vr == "UR") {
      if (!in.read(reinterpret_cast<char*>(element + 8), 4)) return std::nullopt;
      length = std::uint64_t(element[8]) | std::uint64_t(element[9]) << 8 |
               std::uint64_t(element[10]) << 16 | std::uint64_t(element[11]) << 24;
      header = 12;
    }
    if (length > 4096) return std::nullopt;  // no meta attribute is that long
    std::string value(std::size_t(length), '\0');
    if (!in.read(value.data(), std::streamsize(length))) return std::nullopt;
    if (number == 0x0000 && length == 4)
      group_end = at + header + 4 + (std::uint64_t(std::uint8_t(value[0])) |
                                     std::uint64_t(std::uint8_t(value[1])) << 8 |
                                     std::uint64_t(std::uint8_t(value[2])) << 16 |
                                     std::uint64_t(std::uint8_t(value[3])) << 24);
    if (number == 0x0010)  // UI values are padded with NUL, some writers pad with a space
      meta.transfer_syntax = value.substr(0, value.find_last_not_of(std::string(" \0", 2)) + 1);
    at += header + length;
  }
  if (group_end && *group_end != at) return std::nullopt;
  meta.dataset_offset = at;
  return meta;
}

}  // namespace

void check_deflated_dataset(const std::string& path) {
  // DCMTK's own reading of the meta header; it stops at the first dataset attribute, unread. A
  // file it cannot read this far fails the same way when it is loaded, before any inflating.
  DcmFileFormat probe;
  if (probe
          .loadFileUntilTag(path.c_str(), EXS_Unknown, EGL_noChange, DCM_MaxReadLength,
                            ERM_autoDetect, DcmTagKey(0x0000, 0x0000))
          .bad())
    return;
  // A transfer syntax UID is at most 64 bytes; a longer value is not one (and reading it would
  // make DCMTK allocate its length).
  DcmElement* uid = nullptr;
  if (probe.getMetaInfo()->findAndGetElement(DCM_TransferSyntaxUID, uid).bad() || !uid ||
      uid->getLengthField() > 64)
    return;
  const std::string syntax = get_text(*probe.getMetaInfo(), DCM_TransferSyntaxUID);
  if (syntax.empty() || DcmXfer(syntax.c_str()).getStreamCompression() == ESC_none) return;

  std::ifstream in(path, std::ios::binary);
  const std::optional<MetaHeader> meta = walk_meta_header(in);
  require(meta && meta->transfer_syntax == syntax,
          "cannot parse DICOM file: malformed meta header before a deflated dataset", path,
          kCorruptFileHint);
  in.clear();
  in.seekg(std::streamoff(meta->dataset_offset));
  const bool positioned = bool(in);
  InflatingReader inflated(in);
  require(positioned && DeflatedDatasetWalk(inflated).dataset() && inflated.complete(),
          "cannot parse DICOM file: the deflated dataset is corrupt or truncated (an attribute is "
          "longer than the data that holds it)",
          path, kCorruptFileHint);
}

}  // namespace vb::dicom
