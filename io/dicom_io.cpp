#include "io/dicom_io.hpp"

#include <dcmtk/config/osconfig.h>  // DCMTK: must come before its other headers
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcdict.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcmetinf.h>
#include <dcmtk/dcmdata/dcpixel.h>
#include <dcmtk/dcmdata/dcpixseq.h>
#include <dcmtk/dcmdata/dcpxitem.h>
#include <dcmtk/dcmdata/dcrledrg.h>
#include <dcmtk/dcmdata/dcuid.h>
#include <dcmtk/dcmdata/dcxfer.h>
#include <dcmtk/dcmjpeg/djdecode.h>
#include <dcmtk/dcmjpls/djdecode.h>
#include <dcmtk/oflog/oflog.h>
#include <unistd.h>
#include <zlib.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <sstream>

#include "engine/error.hpp"
#include "io/atomic_file.hpp"
#include "voxbreast/config.hpp"

namespace fs = std::filesystem;

namespace vb {
namespace {

// ---- DCMTK set-up ----------------------------------------------------------------------------

/// Once per process: silence DCMTK's logger (library code must not write to stderr; errors reach
/// the caller as vb::Error) and register the JPEG, JPEG-LS and RLE decoders.
void init_dcmtk() {
  static std::once_flag once;
  std::call_once(once, [] {
    OFLog::getLogger("dcmtk").setLogLevel(OFLogger::OFF_LOG_LEVEL);
    DJDecoderRegistration::registerCodecs();
    DJLSDecoderRegistration::registerCodecs();
    DcmRLEDecoderRegistration::registerCodecs();
  });
  require(dcmDataDict.isDictionaryLoaded(), "the DICOM data dictionary is not loaded", {},
          "install DCMTK's dictionary (dicom.dic) or point DCMDICTPATH at it");
}

// ---- attributes carried from a source series to derived series --------------------------------

/// Patient and study attributes (plus the character set they are encoded in).
const std::array<DcmTagKey, 13> kCarriedTags = {DCM_SpecificCharacterSet,
                                                DCM_PatientName,
                                                DCM_PatientID,
                                                DCM_PatientBirthDate,
                                                DCM_PatientSex,
                                                DCM_StudyInstanceUID,
                                                DCM_StudyID,
                                                DCM_StudyDate,
                                                DCM_StudyTime,
                                                DCM_AccessionNumber,
                                                DCM_ReferringPhysicianName,
                                                DCM_StudyDescription,
                                                DCM_FrameOfReferenceUID};

constexpr const char* kSourceSeriesKey = "source_series_uid";
constexpr const char* kCorruptFileHint =
    "the file may be truncated or corrupt; remove or replace it";

/// "gggg,eeee" in upper-case hex, as the standard prints tags.
std::string tag_key_text(const DcmTagKey& key) {
  char text[10];
  std::snprintf(text, sizeof text, "%04X,%04X", unsigned(key.getGroup()),
                unsigned(key.getElement()));
  return text;
}

std::optional<DcmTagKey> parse_tag_key(const std::string& text) {
  unsigned group = 0, element = 0;
  char tail = 0;
  if (text.size() != 9 || std::sscanf(text.c_str(), "%4x,%4x%c", &group, &element, &tail) != 2)
    return std::nullopt;
  return DcmTagKey(Uint16(group), Uint16(element));
}

// ---- reading attributes ----------------------------------------------------------------------

/// All values joined by '\', "" when absent.
std::string get_text(DcmItem& item, const DcmTagKey& key) {
  OFString value;
  return item.findAndGetOFStringArray(key, value).good() ? std::string(value.c_str()) : "";
}

std::optional<double> get_number(DcmItem& item, const DcmTagKey& key, unsigned long pos = 0) {
  Float64 value = 0;
  if (item.findAndGetFloat64(key, value, pos).bad() || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::string tag_name(const DcmTagKey& key) {
  return DcmTag(key).getTagName() + std::string(" (") + tag_key_text(key) + ")";
}

/// `count` numbers of a required attribute; throws naming the file when missing or malformed.
template <int count>
Eigen::Matrix<double, count, 1> require_numbers(DcmItem& item, const DcmTagKey& key,
                                                const std::string& path) {
  Eigen::Matrix<double, count, 1> values;
  for (int n = 0; n < count; ++n) {
    const auto value = get_number(item, key, unsigned(n));
    require(
        value.has_value(),
        "missing or malformed " + tag_name(key) + " (needs " + std::to_string(count) + " numbers)",
        path);
    values[n] = *value;
  }
  return values;
}

Uint16 get_uint16(DcmItem& item, const DcmTagKey& key, Uint16 fallback) {
  Uint16 value = fallback;
  return item.findAndGetUint16(key, value).good() ? value : fallback;
}

// ---- deflated datasets -----------------------------------------------------------------------
//
// DCMTK reads a deflated dataset (Deflated Explicit VR Little Endian) through zlib, where it
// cannot skip over a value to find the stream too short: it allocates each value as long as its
// length field says before reading it (a 1 kB file can ask for 4 GiB). In a plain file it skips
// large values and reads them on first access, so a false length only ends the parse. Hence a
// deflated dataset is walked here first, inflated in a fixed buffer as DCMTK will inflate it:
// every length it holds must be backed by inflated bytes before DCMTK reads it.

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
      if (status == Z_STREAM_END) ended_ = true;
      else if (status != Z_OK) ok_ = false;
    }
    end_ = output_.size() - z_.avail_out;
    return end_ > 0;
  }

  std::ifstream& in_;
  z_stream z_{};
  bool ok_ = false, ended_ = false;
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

/// For a file DCMTK would read as a deflated dataset: the walk above, before DCMTK reads it.
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
  require(positioned && DeflatedDatasetWalk(inflated).dataset(),
          "cannot parse DICOM file: the deflated dataset is corrupt or truncated (an attribute is "
          "longer than the data that holds it)",
          path, kCorruptFileHint);
}

// ---- scanning a folder -----------------------------------------------------------------------

/// A DICOM file whose attributes up to (not including) the pixel data are loaded.
struct DicomHeader {
  std::string path;
  std::unique_ptr<DcmFileFormat> file;
  DcmDataset& data() const { return *file->getDataset(); }
  std::string series_uid() const { return get_text(data(), DCM_SeriesInstanceUID); }
};

enum class FileKind { part10, bare_dataset, other };

/// Part 10 files carry "DICM" after a 128-byte preamble; files without it are tried as bare
/// datasets only when they start with a group 0002 or 0008 tag, so arbitrary files are never
/// parsed.
FileKind sniff(const std::string& path) {
  std::array<char, 132> head{};
  std::ifstream in(path, std::ios::binary);
  in.read(head.data(), head.size());
  const auto got = in.gcount();
  if (got == 132 && std::string(&head[128], 4) == "DICM") return FileKind::part10;
  const bool dicom_group_first = got >= 8 && (head[0] == 0x02 || head[0] == 0x08) && head[1] == 0;
  return dicom_group_first ? FileKind::bare_dataset : FileKind::other;
}

/// The header of a DICOM file that belongs to a series; nullopt for other files.
std::optional<DicomHeader> load_header(const std::string& path) {
  const FileKind kind = sniff(path);
  if (kind == FileKind::other) return std::nullopt;
  if (kind == FileKind::part10) check_deflated_dataset(path);
  auto file = std::make_unique<DcmFileFormat>();
  const OFCondition status = file->loadFileUntilTag(
      path.c_str(), EXS_Unknown, EGL_noChange, DCM_MaxReadLength,
      kind == FileKind::part10 ? ERM_autoDetect : ERM_dataset, DCM_PixelData);
  if (status.bad()) {
    if (kind == FileKind::bare_dataset) return std::nullopt;  // a guess that did not pan out
    throw Error(std::string("cannot parse DICOM file: ") + status.text(), path, kCorruptFileHint);
  }
  DicomHeader header{path, std::move(file)};
  if (!header.series_uid().empty()) return header;
  // DCMTK accepts a file cut between two attributes, so a missing series UID may mean truncation;
  // only a DICOMDIR is a Part 10 file outside any series.
  const bool dicomdir = get_text(*header.file->getMetaInfo(), DCM_MediaStorageSOPClassUID) ==
                        UID_MediaStorageDirectoryStorage;
  require(kind == FileKind::bare_dataset || dicomdir,
          "DICOM file without SeriesInstanceUID (0020,000E)", path, kCorruptFileHint);
  return std::nullopt;
}

std::vector<DicomHeader> scan_folder(const std::string& dir) {
  init_dcmtk();
  std::error_code ec;
  require(fs::is_directory(dir, ec), "not a folder", dir, "give the folder of a DICOM series");
  std::vector<std::string> paths;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.is_regular_file()) paths.push_back(entry.path().string());
  require(!ec, "cannot list folder: " + ec.message(), dir);
  std::sort(paths.begin(), paths.end());  // deterministic order of files and errors

  std::vector<DicomHeader> headers;
  for (const auto& path : paths)
    if (auto header = load_header(path)) headers.push_back(std::move(*header));
  return headers;
}

using SeriesMap = std::map<std::string, std::vector<const DicomHeader*>>;

SeriesMap group_by_series(const std::vector<DicomHeader>& headers) {
  SeriesMap series;
  for (const auto& header : headers) series[header.series_uid()].push_back(&header);
  return series;
}

DicomSeriesInfo describe(const std::string& uid, const std::vector<const DicomHeader*>& files) {
  DcmDataset& first = files.front()->data();
  return {uid, get_text(first, DCM_Modality), get_text(first, DCM_SeriesDescription),
          int(files.size())};
}

std::string series_listing(const SeriesMap& series) {
  std::string text;
  for (const auto& [uid, files] : series) {
    const DicomSeriesInfo info = describe(uid, files);
    text += "\n  " + info.series_uid + "  " + info.modality + "  \"" + info.description + "\"  " +
            std::to_string(info.files) + " files";
  }
  return text;
}

const std::vector<const DicomHeader*>& choose_series(const SeriesMap& series,
                                                     const std::string& uid,
                                                     const std::string& dir) {
  require(!series.empty(), "no DICOM series in the folder", dir,
          "give the folder that holds the series' files");
  if (uid.empty()) {
    require(
        series.size() == 1,
        "the folder holds " + std::to_string(series.size()) + " series:" + series_listing(series),
        dir, "choose one with --series UID");
    return series.begin()->second;
  }
  const auto found = series.find(uid);
  require(found != series.end(),
          "no series " + uid + " in the folder; it holds:" + series_listing(series), dir,
          "choose one of the listed UIDs with --series UID");
  return found->second;
}

// ---- slice geometry --------------------------------------------------------------------------

/// Where one slice lies (mm, LPS) and what its pixel grid is.
struct Slice {
  std::string path;
  Eigen::Vector3d position_mm;    ///< ImagePositionPatient: centre of the first pixel
  Eigen::Vector3d row_direction;  ///< along a row: the direction of increasing column index
  Eigen::Vector3d column_direction;
  double row_spacing_mm = 0;     ///< PixelSpacing[0]: between rows, i.e. along a column
  double column_spacing_mm = 0;  ///< PixelSpacing[1]: between columns, i.e. along a row
  int rows = 0, columns = 0;
  double along_normal_mm = 0;  ///< position · slice normal, the sort key
};

Slice read_slice_geometry(const DicomHeader& header) {
  DcmDataset& data = header.data();
  const Eigen::Matrix<double, 6, 1> cosines =
      require_numbers<6>(data, DCM_ImageOrientationPatient, header.path);
  const Eigen::Vector2d pixel_spacing = require_numbers<2>(data, DCM_PixelSpacing, header.path);
  Slice slice{header.path,
              require_numbers<3>(data, DCM_ImagePositionPatient, header.path),
              cosines.head<3>(),
              cosines.tail<3>(),
              pixel_spacing[0],
              pixel_spacing[1],
              get_uint16(data, DCM_Rows, 0),
              get_uint16(data, DCM_Columns, 0)};
  require(slice.rows > 0 && slice.columns > 0, "missing Rows/Columns", header.path);
  require(pixel_spacing.minCoeff() > 0, "PixelSpacing must be positive", header.path);
  const bool orthonormal = std::abs(slice.row_direction.norm() - 1) < 1e-3 &&
                           std::abs(slice.column_direction.norm() - 1) < 1e-3 &&
                           std::abs(slice.row_direction.dot(slice.column_direction)) < 1e-3;
  require(orthonormal, "ImageOrientationPatient is not two orthogonal unit vectors", header.path);
  slice.row_direction.normalize();
  slice.column_direction.normalize();
  return slice;
}

/// All slices must share one pixel grid and orientation: anything else is not one volume.
void check_same_grid(const std::vector<Slice>& slices) {
  const Slice& first = slices.front();
  auto close = [](double a, double b) {
    return std::abs(a - b) <= 1e-4 * std::max(1.0, std::abs(a));
  };
  for (const Slice& s : slices) {
    require(s.rows == first.rows && s.columns == first.columns,
            "mixed image sizes in one series: " + std::to_string(s.columns) + "×" +
                std::to_string(s.rows) + " vs " + std::to_string(first.columns) + "×" +
                std::to_string(first.rows) + " in " + first.path,
            s.path, "the series is not one volume; choose another series");
    require(close(s.row_spacing_mm, first.row_spacing_mm) &&
                close(s.column_spacing_mm, first.column_spacing_mm),
            "mixed PixelSpacing in one series (differs from " + first.path + ")", s.path,
            "the series is not one volume; choose another series");
    const double turn = std::max((s.row_direction - first.row_direction).norm(),
                                 (s.column_direction - first.column_direction).norm());
    require(turn < 1e-4,
            "mixed ImageOrientationPatient in one series (differs from " + first.path +
                "; a localizer mixed in?)",
            s.path, "the series is not one volume; choose another series");
  }
}

std::string mm_text(double mm) {
  std::ostringstream text;
  text.precision(6);
  text << mm << " mm";
  return text.str();
}

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

/// The k spacing of a sorted stack (mm). Duplicates are always errors; uneven gaps are errors
/// unless `allow_gaps`, then warnings and the median gap is used.
double stack_spacing_mm(const std::vector<Slice>& sorted, bool allow_gaps,
                        std::vector<std::string>& warnings) {
  std::vector<double> gaps;
  for (std::size_t n = 1; n < sorted.size(); ++n) {
    const double gap = sorted[n].along_normal_mm - sorted[n - 1].along_normal_mm;
    require(gap > 1e-3,
            "duplicate slice position " + mm_text(sorted[n].along_normal_mm) +
                " along the normal, shared with " + sorted[n - 1].path,
            sorted[n].path, "remove the duplicate file or choose another series");
    gaps.push_back(gap);
  }
  const double typical = median(gaps);
  for (std::size_t n = 0; n < gaps.size(); ++n) {
    if (std::abs(gaps[n] - typical) <= 0.01 * typical) continue;
    const std::string what = "uneven slice spacing: gap of " + mm_text(gaps[n]) +
                             " between slices " + std::to_string(n) + " and " +
                             std::to_string(n + 1) + " (" + sorted[n].path + ", " +
                             sorted[n + 1].path + "); the median gap is " + mm_text(typical);
    require(allow_gaps, what, {}, "a slice may be missing; allow gaps to read it anyway");
    warnings.push_back(what + "; read with the median gap, so slices beyond it are misplaced by " +
                       mm_text(gaps[n] - typical));
  }
  return typical;
}

/// A single slice has no neighbour to measure: take its declared spacing or thickness.
double single_slice_spacing_mm(const DicomHeader& header) {
  for (const DcmTagKey& key : {DCM_SpacingBetweenSlices, DCM_SliceThickness})
    if (const auto value = get_number(header.data(), key); value && *value > 0) return *value;
  throw Error("a single slice without SpacingBetweenSlices or SliceThickness has no thickness",
              header.path, "add SliceThickness (0018,0050) to the file");
}

/// Gantry-tilted (sheared) stacks step sideways from slice to slice; an orthogonal affine would
/// misplace them, so they are refused.
void check_stacked_along_normal(const std::vector<Slice>& sorted, const Eigen::Vector3d& normal) {
  const Slice& first = sorted.front();
  const double tolerance = 0.1 * std::min(first.row_spacing_mm, first.column_spacing_mm);
  for (const Slice& s : sorted) {
    const Eigen::Vector3d step = s.position_mm - first.position_mm;
    const double sideways = (step - step.dot(normal) * normal).norm();
    require(sideways <= tolerance,
            "slices are not stacked along the slice normal (offset " + mm_text(sideways) +
                " sideways from " + first.path + "; gantry tilt?)",
            s.path, "resample the series onto an orthogonal grid first");
  }
}

struct StackGeometry {
  std::vector<const DicomHeader*> files;  ///< sorted along the slice normal
  Eigen::Matrix4d affine_lps_m = Eigen::Matrix4d::Identity();
  int rows = 0, columns = 0;
};

StackGeometry stack_geometry(const std::vector<const DicomHeader*>& files, bool allow_gaps,
                             std::vector<std::string>& warnings) {
  std::vector<Slice> slices;
  for (const DicomHeader* header : files) slices.push_back(read_slice_geometry(*header));
  check_same_grid(slices);
  const Slice& first = slices.front();
  const Eigen::Vector3d normal = first.row_direction.cross(first.column_direction);
  std::vector<std::size_t> order(slices.size());
  for (std::size_t n = 0; n < slices.size(); ++n) {
    slices[n].along_normal_mm = slices[n].position_mm.dot(normal);
    order[n] = n;
  }
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return slices[a].along_normal_mm < slices[b].along_normal_mm;
  });
  std::vector<Slice> sorted;
  StackGeometry stack;
  for (std::size_t n : order) {
    sorted.push_back(slices[n]);
    stack.files.push_back(files[n]);
  }
  check_stacked_along_normal(sorted, normal);
  const double spacing_mm = sorted.size() > 1 ? stack_spacing_mm(sorted, allow_gaps, warnings)
                                              : single_slice_spacing_mm(*stack.files.front());

  constexpr double m_per_mm = 1e-3;
  stack.affine_lps_m.block<3, 1>(0, 0) = first.row_direction * first.column_spacing_mm * m_per_mm;
  stack.affine_lps_m.block<3, 1>(0, 1) = first.column_direction * first.row_spacing_mm * m_per_mm;
  stack.affine_lps_m.block<3, 1>(0, 2) = normal * spacing_mm * m_per_mm;
  stack.affine_lps_m.block<3, 1>(0, 3) = sorted.front().position_mm * m_per_mm;
  stack.rows = first.rows;
  stack.columns = first.columns;
  return stack;
}

// ---- pixel data ------------------------------------------------------------------------------
//
// A slice's pixel attributes and the size of its pixel data are checked before any memory is
// committed to its pixels: before the volume is allocated (Rows × Columns × slices floats) and
// before DCMTK decodes compressed data, since its decoders allocate their output from Rows,
// Columns, SamplesPerPixel and BitsAllocated before they look at the compressed stream.

/// Largest volume read: 2^31 voxels (8 GiB of float values).
constexpr std::uint64_t kMaxVoxels = std::uint64_t(1) << 31;
/// Compressed (encapsulated) pixel data may decode to at most kMaxCompressionRatio times the
/// file's size, plus kCompressedAllowanceBytes for any file. Real CT slices compress far less;
/// JPEG-LS can beat 1024:1 only on large uniform areas, and the allowance covers those for slices
/// up to 4096 × 4096 at 16 bits. Without this bound a file of a few hundred bytes could make
/// DCMTK's decoder allocate gigabytes.
constexpr std::uint64_t kMaxCompressionRatio = 1024;
constexpr std::uint64_t kCompressedAllowanceBytes = std::uint64_t(32) << 20;
/// A deflated dataset (Deflated Explicit VR Little Endian) inflates at most 1032:1.
constexpr std::uint64_t kMaxDeflateRatio = 1032;

/// How one slice's pixels are stored: one frame, one sample per pixel.
struct PixelLayout {
  int bits_allocated = 0, bits_stored = 0;
  bool is_signed = false;
  std::uint64_t pixels = 0;  ///< Rows × Columns
  std::uint64_t bytes = 0;   ///< pixels × BitsAllocated / 8
};

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

/// A slice file (values of large elements are loaded on access) whose pixel attributes and pixel
/// data size have been checked.
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

/// Decodes one slice's pixels into `out` (rows × columns, column index fastest) in rescaled units.
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

void carry_tags(DcmDataset& data, ImageVolume& volume) {
  for (const DcmTagKey& key : kCarriedTags) {
    OFString value;
    if (data.findAndGetOFStringArray(key, value).good())
      volume.dicom_tags[tag_key_text(key)] = value.c_str();
  }
  volume.dicom_tags[kSourceSeriesKey] = get_text(data, DCM_SeriesInstanceUID);
}

// ---- writing ---------------------------------------------------------------------------------

/// Slice grid of a volume in DICOM terms (mm, LPS).
struct WriteGeometry {
  Eigen::Vector3d row_direction, column_direction;   ///< voxel axes i and j, unit
  double column_spacing_mm = 0, row_spacing_mm = 0;  ///< |axis i|, |axis j|
  Eigen::Vector3d origin_mm, slice_step_mm;          ///< voxel (0,0,0), axis k
};

WriteGeometry write_geometry(const ImageVolume& ct, const std::string& dir) {
  const Eigen::Matrix3d axes_mm = ct.affine_lps_m.topLeftCorner<3, 3>() * 1e3;
  WriteGeometry g;
  g.column_spacing_mm = axes_mm.col(0).norm();
  g.row_spacing_mm = axes_mm.col(1).norm();
  const double slice_spacing_mm = axes_mm.col(2).norm();
  require(g.column_spacing_mm > 0 && g.row_spacing_mm > 0 && slice_spacing_mm > 0,
          "the volume's affine has a zero-length axis", dir);
  g.row_direction = axes_mm.col(0) / g.column_spacing_mm;
  g.column_direction = axes_mm.col(1) / g.row_spacing_mm;
  const Eigen::Vector3d k_direction = axes_mm.col(2) / slice_spacing_mm;
  const double shear = std::max({std::abs(g.row_direction.dot(g.column_direction)),
                                 std::abs(g.row_direction.dot(k_direction)),
                                 std::abs(g.column_direction.dot(k_direction))});
  require(shear < 1e-4, "the volume's affine is sheared (voxel axes not perpendicular)", dir,
          "DICOM CT slices need perpendicular axes; resample the volume first");
  g.origin_mm = ct.affine_lps_m.topRightCorner<3, 1>() * 1e3;
  g.slice_step_mm = axes_mm.col(2);
  return g;
}

/// Stored = round((HU − intercept) / slope) in int16.
struct Rescale {
  double slope = 1, intercept = -1024;
};

/// Slope 1 / intercept −1024 (the CT convention) when the rounded HU fit int16 that way,
/// else a slope spreading [min, max] over the whole int16 range.
Rescale choose_rescale(const std::vector<float>& values, const std::string& dir) {
  const auto not_finite =
      std::find_if(values.begin(), values.end(), [](float v) { return !std::isfinite(v); });
  require(
      not_finite == values.end(),
      "the volume holds a non-finite value at index " + std::to_string(not_finite - values.begin()),
      dir);
  const auto [low, high] = std::minmax_element(values.begin(), values.end());
  Rescale rescale;
  const double stored_low = std::round(double(*low)) - rescale.intercept;
  const double stored_high = std::round(double(*high)) - rescale.intercept;
  if (stored_low >= INT16_MIN && stored_high <= INT16_MAX) return rescale;
  rescale.slope = (double(*high) - double(*low)) / (double(INT16_MAX) - double(INT16_MIN));
  rescale.intercept = double(*low) - double(INT16_MIN) * rescale.slope;
  return rescale;
}

std::vector<Uint16> stored_pixels(const float* hu, std::size_t count, const Rescale& rescale) {
  std::vector<Uint16> stored(count);
  for (std::size_t n = 0; n < count; ++n) {
    const double value = std::round((double(hu[n]) - rescale.intercept) / rescale.slope);
    stored[n] = Uint16(std::int16_t(std::clamp(value, double(INT16_MIN), double(INT16_MAX))));
  }
  return stored;
}

/// Decimal string (DS) of at most 16 characters, as precise as fits.
std::string ds_text(double value) {
  if (std::abs(value) < 1e-12) value = 0;  // avoid "1e-17"-style noise from rotations
  char text[32];
  for (int digits = 15; digits > 1; --digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, value);
    if (std::string(text).size() <= 16) break;
  }
  return text;
}

template <class Vector>
std::string ds_list(const Vector& values) {
  std::string text;
  for (int n = 0; n < int(values.size()); ++n) text += (n ? "\\" : "") + ds_text(values[n]);
  return text;
}

/// The UID root is DCMTK's (OFFIS-registered) site root; replace it here with your own
/// registered root if your site requires one.
std::string new_uid(const char* root) {
  char uid[100];
  return dcmGenerateUniqueIdentifier(uid, root);
}

/// Attributes shared by every slice of the written series.
struct SeriesAttributes {
  std::map<std::string, std::string> carried;  ///< "gggg,eeee" → value
  std::string series_uid, series_description, derivation;
  Rescale rescale;
  WriteGeometry geometry;
};

std::map<std::string, std::string> carried_attributes(const ImageVolume& ct) {
  std::map<std::string, std::string> carried;
  for (const auto& [key, value] : ct.dicom_tags) {
    const auto tag = parse_tag_key(key);
    if (tag && std::find(kCarriedTags.begin(), kCarriedTags.end(), *tag) != kCarriedTags.end())
      carried[tag_key_text(*tag)] = value;
  }
  // Without a source study (NIfTI, phantom) the series starts its own study and frame.
  carried.try_emplace(tag_key_text(DCM_StudyInstanceUID), new_uid(SITE_STUDY_UID_ROOT));
  carried.try_emplace(tag_key_text(DCM_FrameOfReferenceUID), new_uid(SITE_INSTANCE_UID_ROOT));
  carried.try_emplace(tag_key_text(DCM_PatientName), "VoxBreast^Phantom");
  carried.try_emplace(tag_key_text(DCM_PatientID), "VOXBREAST");
  return carried;
}

class DatasetWriter {
 public:
  DatasetWriter(DcmDataset& data, const std::string& path) : data_(data), path_(path) {}
  void text(const DcmTagKey& key, const std::string& value) {
    check(data_.putAndInsertOFStringArray(key, value.c_str()), key);
  }
  void number(const DcmTagKey& key, Uint16 value) {
    check(data_.putAndInsertUint16(key, value), key);
  }
  void words(const DcmTagKey& key, const std::vector<Uint16>& values) {
    check(data_.putAndInsertUint16Array(key, values.data(), values.size()), key);
  }

 private:
  void check(const OFCondition& status, const DcmTagKey& key) {
    require(status.good(), "cannot set " + tag_name(key) + ": " + status.text(), path_);
  }
  DcmDataset& data_;
  const std::string& path_;
};

void write_slice(const std::string& path, const SeriesAttributes& series, const ImageVolume& ct,
                 int k) {
  DcmFileFormat file;
  DatasetWriter put(*file.getDataset(), path);
  for (const auto& [key, value] : series.carried) put.text(*parse_tag_key(key), value);
  // Type 2 attributes: present even when empty.
  for (const DcmTagKey& key : {DCM_PatientBirthDate, DCM_PatientSex, DCM_StudyDate, DCM_StudyTime,
                               DCM_ReferringPhysicianName, DCM_StudyID, DCM_AccessionNumber})
    if (!series.carried.count(tag_key_text(key))) put.text(key, "");

  put.text(DCM_SOPClassUID, UID_CTImageStorage);
  put.text(DCM_SOPInstanceUID, new_uid(SITE_INSTANCE_UID_ROOT));
  put.text(DCM_SeriesInstanceUID, series.series_uid);
  put.text(DCM_Modality, "CT");
  put.text(DCM_SeriesNumber, "9000");
  put.text(DCM_SeriesDescription, series.series_description);
  put.text(DCM_ImageType, "DERIVED\\SECONDARY");
  put.text(DCM_DerivationDescription, series.derivation);
  put.text(DCM_Manufacturer, "VoxBreast");
  put.text(DCM_SoftwareVersions, config::version);
  put.text(DCM_PositionReferenceIndicator, "");
  put.text(DCM_KVP, "");
  put.text(DCM_AcquisitionNumber, "");
  put.text(DCM_InstanceNumber, std::to_string(k + 1));

  const WriteGeometry& g = series.geometry;
  const Eigen::Vector3d position = g.origin_mm + double(k) * g.slice_step_mm;
  Eigen::Matrix<double, 6, 1> cosines;
  cosines << g.row_direction, g.column_direction;
  put.text(DCM_ImagePositionPatient, ds_list(position));
  put.text(DCM_ImageOrientationPatient, ds_list(cosines));
  put.text(DCM_PixelSpacing, ds_list(Eigen::Vector2d(g.row_spacing_mm, g.column_spacing_mm)));
  put.text(DCM_SliceThickness, ds_text(g.slice_step_mm.norm()));
  put.text(DCM_SpacingBetweenSlices, ds_text(g.slice_step_mm.norm()));
  put.text(DCM_SliceLocation, ds_text(position.dot(g.row_direction.cross(g.column_direction))));

  put.number(DCM_SamplesPerPixel, 1);
  put.text(DCM_PhotometricInterpretation, "MONOCHROME2");
  put.number(DCM_Rows, Uint16(ct.dims[1]));
  put.number(DCM_Columns, Uint16(ct.dims[0]));
  put.number(DCM_BitsAllocated, 16);
  put.number(DCM_BitsStored, 16);
  put.number(DCM_HighBit, 15);
  put.number(DCM_PixelRepresentation, 1);
  put.text(DCM_RescaleIntercept, ds_text(series.rescale.intercept));
  put.text(DCM_RescaleSlope, ds_text(series.rescale.slope));
  put.text(DCM_RescaleType, "HU");
  const std::size_t slice_voxels = std::size_t(ct.dims[0]) * std::size_t(ct.dims[1]);
  put.words(DCM_PixelData,
            stored_pixels(&ct.values[ct.linear_index(0, 0, k)], slice_voxels, series.rescale));

  const OFCondition status = file.saveFile(path.c_str(), EXS_LittleEndianExplicit);
  require(status.good(), std::string("cannot write DICOM file: ") + status.text(), path);
}

/// A hidden sibling folder that disappears unless it is renamed into place.
class StagingFolder {
 public:
  explicit StagingFolder(const fs::path& final_dir) : final_(final_dir) {
    static std::atomic<unsigned long> counter{0};
    path_ = final_.parent_path() / ("." + final_.filename().string() + ".tmp-" +
                                    std::to_string(::getpid()) + "-" + std::to_string(counter++));
    std::error_code ec;
    fs::create_directories(path_, ec);
    require(!ec, "cannot create folder: " + ec.message(), path_.string());
  }
  ~StagingFolder() {
    if (committed_) return;
    std::error_code ignored;  // best effort: a destructor must not throw
    fs::remove_all(path_, ignored);
  }
  StagingFolder(const StagingFolder&) = delete;
  StagingFolder& operator=(const StagingFolder&) = delete;

  const fs::path& path() const { return path_; }
  /// Renames onto the final folder, which POSIX allows only while that one is absent or empty.
  void commit() {
    std::error_code ec;
    fs::rename(path_, final_, ec);
    require(!ec, "cannot rename '" + path_.string() + "' into place: " + ec.message(),
            final_.string(), "the output folder must not exist or be empty");
    committed_ = true;
  }

 private:
  fs::path final_, path_;
  bool committed_ = false;
};

fs::path normal_output_path(const std::string& dir) {
  fs::path path = fs::absolute(fs::path(dir)).lexically_normal();
  if (path.filename().empty()) path = path.parent_path();  // "out/" → "out"
  return path;
}

fs::path clean_output_path(const std::string& dir) {
  const fs::path path = normal_output_path(dir);
  std::error_code ec;
  const bool occupied =
      fs::exists(path, ec) && !(fs::is_directory(path, ec) && fs::is_empty(path, ec));
  require(!occupied, "the output path exists and is not an empty folder", dir,
          "choose a new folder; a DICOM series is never written over existing files");
  ensure_output_dir(path.parent_path().string());
  return path;
}

void check_writable(const ImageVolume& ct, const std::string& dir) {
  require(ct.dims[0] > 0 && ct.dims[1] > 0 && ct.dims[2] > 0, "the volume is empty", dir);
  require(ct.dims[0] <= 65535 && ct.dims[1] <= 65535,
          "a slice is too large for DICOM (more than 65535 rows or columns)", dir);
  require(ct.values.size() == ct.voxel_count(),
          "the volume's values do not match its dims (" + std::to_string(ct.values.size()) +
              " values for " + std::to_string(ct.voxel_count()) + " voxels)",
          dir);
}

std::string slice_file_name(int k) {
  char name[32];
  std::snprintf(name, sizeof name, "CT%05d.dcm", k + 1);
  return name;
}

/// A folder this writer may replace whole: absent, or holding only regular files named as
/// slice_file_name names them (an earlier series of this writer). Returns whether it exists.
bool check_own_series_folder(const fs::path& path, const std::string& dir) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return false;
  require(fs::is_directory(path, ec) && !fs::is_symlink(path, ec), "the output path exists and is not a folder",
          dir, "remove it or choose another output folder");
  for (const fs::directory_entry& entry : fs::directory_iterator(path, ec)) {
    const std::string name = entry.path().filename().string();
    int number = 0;  // exactly the name slice_file_name gives some slice
    const bool slice_name = std::sscanf(name.c_str(), "CT%5d", &number) == 1 && number >= 1 &&
                            slice_file_name(number - 1) == name;
    require(slice_name && entry.is_regular_file(ec) && !entry.is_symlink(ec),
            "the output folder holds '" + name + "', which is not a slice of an earlier VoxBreast series", dir,
            "a DICOM series replaces only its own earlier series: move it away or choose another output folder");
  }
  require(!ec, "cannot list the output folder: " + ec.message(), dir);
  return true;
}

/// read_dicom_series without its guard against running out of memory.
ImageVolume read_series(const std::string& dir, const DicomReadOptions& options,
                        std::vector<std::string>* warnings) {
  const std::vector<DicomHeader> headers = scan_folder(dir);
  const SeriesMap series = group_by_series(headers);
  const auto& files = choose_series(series, options.series_uid, dir);

  ImageVolume volume;
  volume.modality = get_text(files.front()->data(), DCM_Modality);
  require(
      options.accept_any_modality || volume.modality == "CT",
      "not a CT series (modality " + (volume.modality.empty() ? "unknown" : volume.modality) + ")",
      files.front()->path, "give a CT series");

  std::vector<std::string> stack_warnings;
  const StackGeometry stack = stack_geometry(files, options.allow_gaps, stack_warnings);
  volume.dims = {stack.columns, stack.rows, int(stack.files.size())};
  const std::uint64_t voxels =
      std::uint64_t(stack.columns) * std::uint64_t(stack.rows) * stack.files.size();
  require(voxels <= kMaxVoxels,
          "the series has " + std::to_string(voxels) + " voxels (" +
              std::to_string(stack.columns) + " x " + std::to_string(stack.rows) + " x " +
              std::to_string(stack.files.size()) + "), more than the " +
              std::to_string(kMaxVoxels) + " read",
          dir, "crop or downsample the series first");
  // Every slice's pixel attributes and pixel data size, before memory is committed to the volume.
  for (const DicomHeader* file : stack.files) {
    PixelLayout layout;
    load_slice(file->path, stack.rows, stack.columns, layout);
  }
  volume.affine_lps_m = stack.affine_lps_m;
  volume.values.resize(volume.voxel_count());
  for (int k = 0; k < volume.dims[2]; ++k)
    read_slice_pixels(stack.files[std::size_t(k)]->path, stack.rows, stack.columns,
                      &volume.values[volume.linear_index(0, 0, k)]);
  carry_tags(stack.files.front()->data(), volume);
  if (warnings) warnings->insert(warnings->end(), stack_warnings.begin(), stack_warnings.end());
  return volume;
}

/// Runs a reader of the folder `dir`; running out of memory is a vb::Error naming the folder.
template <class Read>
auto guard_memory(const std::string& dir, Read&& read) {
  try {
    return read();
  } catch (const std::bad_alloc&) {
    throw Error("not enough memory to read the DICOM series", dir,
                "free memory, or crop or downsample the series first");
  }
}

}  // namespace

std::vector<DicomSeriesInfo> list_dicom_series(const std::string& dir) {
  return guard_memory(dir, [&] {
    const std::vector<DicomHeader> headers = scan_folder(dir);
    std::vector<DicomSeriesInfo> infos;
    for (const auto& [uid, files] : group_by_series(headers)) infos.push_back(describe(uid, files));
    return infos;
  });
}

ImageVolume read_dicom_series(const std::string& dir, const DicomReadOptions& options,
                              std::vector<std::string>* warnings) {
  return guard_memory(dir, [&] { return read_series(dir, options, warnings); });
}

ImageVolume read_dicom_series(const std::string& dir, const std::string& series_uid,
                              bool allow_gaps, std::vector<std::string>* warnings) {
  DicomReadOptions options;
  options.series_uid = series_uid;
  options.allow_gaps = allow_gaps;
  return read_dicom_series(dir, options, warnings);
}

namespace {

/// The new series' attributes: geometry, rescale, carried patient and study, fresh UIDs.
SeriesAttributes series_attributes(const ImageVolume& ct, const std::string& dir,
                                   const std::string& series_description) {
  SeriesAttributes series;
  series.geometry = write_geometry(ct, dir);
  series.rescale = choose_rescale(ct.values, dir);
  series.carried = carried_attributes(ct);
  series.series_uid = new_uid(SITE_SERIES_UID_ROOT);
  series.series_description = series_description;
  const auto source = ct.dicom_tags.find(kSourceSeriesKey);
  series.derivation = "VoxBreast " + std::string(config::version) + " output" +
                      (source != ct.dicom_tags.end() ? " from series " + source->second : "");
  return series;
}

void write_slices(const StagingFolder& staging, const ImageVolume& ct, const std::string& dir,
                  const std::string& series_description) {
  const SeriesAttributes series = series_attributes(ct, dir, series_description);
  for (int k = 0; k < ct.dims[2]; ++k)
    write_slice((staging.path() / slice_file_name(k)).string(), series, ct, k);
}

}  // namespace

void write_dicom_series(const std::string& dir, const ImageVolume& ct,
                        const std::string& series_description) {
  init_dcmtk();
  check_writable(ct, dir);
  StagingFolder staging(clean_output_path(dir));
  write_slices(staging, ct, dir, series_description);
  staging.commit();
}

void check_dicom_series_replaceable(const std::string& dir) { check_own_series_folder(normal_output_path(dir), dir); }

void replace_dicom_series(const std::string& dir, const ImageVolume& ct,
                          const std::string& series_description) {
  init_dcmtk();
  check_writable(ct, dir);
  const fs::path final_dir = normal_output_path(dir);
  const bool earlier = check_own_series_folder(final_dir, dir);
  ensure_output_dir(final_dir.parent_path().string());
  StagingFolder staging(final_dir);
  write_slices(staging, ct, dir, series_description);
  if (!earlier) {
    staging.commit();
    return;
  }
  // Swap by two renames, so the folder never holds slices of both series; the old one goes last.
  const fs::path old_dir = final_dir.parent_path() / ("." + final_dir.filename().string() + ".old-" +
                                                      std::to_string(::getpid()));
  std::error_code ec;
  fs::rename(final_dir, old_dir, ec);
  require(!ec, "cannot move the earlier series aside: " + ec.message(), dir);
  try {
    staging.commit();
  } catch (...) {
    std::error_code ignored;
    fs::rename(old_dir, final_dir, ignored);  // put the earlier series back
    throw;
  }
  fs::remove_all(old_dir, ec);
  require(!ec, "the new series is in place, but the earlier one could not be removed: " + ec.message(),
          old_dir.string());
}

}  // namespace vb
