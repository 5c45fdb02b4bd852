// Writing a DICOM CT series (io/dicom_io.hpp): one file per slice, staged in a hidden sibling
// folder and renamed into place.
#include <dcmtk/config/osconfig.h>  // DCMTK: must come before its other headers
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcistrmf.h>
#include <dcmtk/dcmdata/dcvrfl.h>
#include <dcmtk/dcmdata/dcuid.h>
#include <dcmtk/dcmdata/dcvrda.h>
#include <dcmtk/dcmdata/dcvrtm.h>
#include <dcmtk/ofstd/ofuuid.h>
#include <openssl/evp.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <tuple>

#include "engine/error.hpp"
#include "io/atomic_file.hpp"
#include "io/system_reason.hpp"
#include "io/dicom_attributes.hpp"
#include "io/dicom_io.hpp"
#include "voxbreast/config.hpp"

namespace fs = std::filesystem;

namespace vb {
using namespace dicom;

namespace {

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

/// An OpenSSL message digest fed piece by piece.
class Digest {
 public:
  explicit Digest(const EVP_MD* kind) : context_(EVP_MD_CTX_new()) {
    require(context_ && EVP_DigestInit_ex(context_, kind, nullptr) == 1, "cannot start an OpenSSL digest");
  }
  ~Digest() { EVP_MD_CTX_free(context_); }
  Digest(const Digest&) = delete;
  Digest& operator=(const Digest&) = delete;
  void add(const void* data, std::size_t bytes) { EVP_DigestUpdate(context_, data, bytes); }
  std::string finish() {
    unsigned char bytes[EVP_MAX_MD_SIZE];
    unsigned int size = 0;
    EVP_DigestFinal_ex(context_, bytes, &size);
    return std::string(reinterpret_cast<const char*>(bytes), size);
  }

 private:
  EVP_MD_CTX* context_;
};

/// SHA-256 of the volume: what a deterministic series' UIDs are derived from.
std::string content_digest(const ImageVolume& ct, const std::string& description) {
  Digest sha(EVP_sha256());
  sha.add(description.data(), description.size());
  sha.add(ct.dims.data(), sizeof ct.dims);
  sha.add(ct.affine_lps_m.data(), sizeof(double) * 16);
  sha.add(ct.values.data(), sizeof(float) * ct.values.size());
  return sha.finish();
}

/// Fresh UIDs, or (deterministic) UIDs named after the volume's content and the UID's role.
class UidSource {
 public:
  UidSource(bool deterministic, const ImageVolume& ct, const std::string& description)
      : digest_(deterministic ? content_digest(ct, description) : std::string()) {}
  std::string operator()(const char* root, const std::string& role) const {
    return digest_.empty() ? new_uid(root) : name_based_uid(digest_ + role);
  }

 private:
  std::string digest_;
};

/// DICOM date and time (DA, TM) of now, local time as DICOM expects.
std::pair<std::string, std::string> now_date_time() {
  OFString date, time;
  DcmDate::getCurrentDate(date);
  DcmTime::getCurrentTime(time, true, false);
  return {date.c_str(), time.c_str()};
}

/// Attributes shared by every slice of the written series.
struct SeriesAttributes {
  std::map<std::string, std::string> carried;  ///< "gggg,eeee" → value
  std::string series_uid, series_description, derivation, patient_position;
  std::string date, time;  ///< of writing; empty for a deterministic series
  std::vector<std::string> instance_uids;  ///< per slice
  std::string source_sop_class;
  std::vector<std::string> source_instances;          ///< per source slice
  std::vector<std::pair<int, int>> source_slices;     ///< per written slice: source slices used
  Rescale rescale;
  WriteGeometry geometry;
};

std::map<std::string, std::string> carried_attributes(const ImageVolume& ct, const UidSource& uid,
                                                      const std::string& date, const std::string& time) {
  std::map<std::string, std::string> carried;
  for (const auto& [key, value] : ct.dicom_tags) {
    const auto tag = parse_tag_key(key);
    if (tag && std::find(kCarriedTags.begin(), kCarriedTags.end(), *tag) != kCarriedTags.end())
      carried[tag_key_text(*tag)] = value;
  }
  // Without a source study (NIfTI, phantom) the series starts its own study and frame, now.
  if (!carried.count(tag_key_text(DCM_StudyInstanceUID))) {
    carried[tag_key_text(DCM_StudyInstanceUID)] = uid(SITE_STUDY_UID_ROOT, "/study");
    carried.try_emplace(tag_key_text(DCM_StudyDate), date);
    carried.try_emplace(tag_key_text(DCM_StudyTime), time);
  }
  carried.try_emplace(tag_key_text(DCM_FrameOfReferenceUID), uid(SITE_INSTANCE_UID_ROOT, "/frame"));
  carried.try_emplace(tag_key_text(DCM_PatientName), "VoxBreast^Phantom");
  carried.try_emplace(tag_key_text(DCM_PatientID), "VOXBREAST");
  return carried;
}

class DatasetWriter {
 public:
  DatasetWriter(DcmItem& data, const std::string& path) : data_(data), path_(path) {}
  void text(const DcmTagKey& key, const std::string& value) {
    check(data_.putAndInsertOFStringArray(key, value.c_str()), key);
  }
  void number(const DcmTagKey& key, Uint16 value) {
    check(data_.putAndInsertUint16(key, value), key);
  }
  void words(const DcmTagKey& key, const std::vector<Uint16>& values) {
    check(data_.putAndInsertUint16Array(key, values.data(), values.size()), key);
  }
  void longs(const DcmTagKey& key, const std::vector<Uint32>& values) {
    check(data_.putAndInsertUint32Array(key, values.data(), values.size()), key);
  }
  void doubles(const DcmTagKey& key, const std::vector<Float64>& values) {
    check(data_.putAndInsertFloat64Array(key, values.data(), values.size()), key);
  }
  void floats(const DcmTagKey& key, const std::vector<Float32>& values) {
    check(data_.putAndInsertFloat32Array(key, values.data(), values.size()), key);
  }
  /// An FL attribute whose `bytes` (little-endian floats) DCMTK reads from `file` only while it
  /// writes the dataset: a large value is never held in memory.
  void floats_from_file(const DcmTagKey& key, const std::string& file, std::size_t bytes) {
    require(bytes % 4 == 0 && bytes < 0xFFFFFFFEu, "the attribute is too large for DICOM", path_);
    auto* element = new DcmFloatingPointSingle(DcmTag(key));
    check(element->createValueFromTempFile(new DcmInputFileStreamFactory(file.c_str(), 0), Uint32(bytes),
                                           EBO_LittleEndian),
          key);
    check(data_.insert(element, /*replaceOld=*/true), key);
  }
  /// Sequence `key` with no items (a type 2 sequence with nothing to say).
  void empty_sequence(const DcmTagKey& key) { check(data_.insertEmptyElement(key), key); }
  /// A new item at the end of sequence `key`.
  DcmItem& item(const DcmTagKey& key) {
    DcmItem* added = nullptr;
    check(data_.findOrCreateSequenceItem(key, added, -2), key);
    return *added;
  }

 private:
  void check(const OFCondition& status, const DcmTagKey& key) {
    require(status.good(), "cannot set " + tag_name(key) + ": " + status.text(), path_);
  }
  DcmItem& data_;
  const std::string& path_;
};

/// The carried patient, study and frame attributes, and the type 2 ones among them empty when absent.
void put_patient_and_study(DatasetWriter& put, const std::map<std::string, std::string>& carried) {
  for (const auto& [key, value] : carried) put.text(*parse_tag_key(key), value);
  for (const DcmTagKey& key : {DCM_PatientBirthDate, DCM_PatientSex, DCM_StudyDate, DCM_StudyTime,
                               DCM_ReferringPhysicianName, DCM_StudyID, DCM_AccessionNumber})
    if (!carried.count(tag_key_text(key))) put.text(key, "");
}

/// A dicom_tags value of the volume, "" when absent.
std::string tag_of(const ImageVolume& volume, const char* key) {
  const auto it = volume.dicom_tags.find(key);
  return it == volume.dicom_tags.end() ? std::string() : it->second;
}

void write_slice(const std::string& path, const SeriesAttributes& series, const ImageVolume& ct,
                 int k) {
  DcmFileFormat file;
  DatasetWriter put(*file.getDataset(), path);
  put_patient_and_study(put, series.carried);

  put.text(DCM_SOPClassUID, UID_CTImageStorage);
  put.text(DCM_SOPInstanceUID, series.instance_uids[std::size_t(k)]);
  put.text(DCM_SeriesInstanceUID, series.series_uid);
  put.text(DCM_Modality, "CT");
  put.text(DCM_SeriesNumber, "9000");
  put.text(DCM_SeriesDescription, series.series_description);
  put.text(DCM_PatientPosition, series.patient_position);
  put.text(DCM_Laterality, "");  // a breast CT may show both sides: unknown
  if (!series.date.empty()) {
    for (const DcmTagKey& key : {DCM_SeriesDate, DCM_ContentDate, DCM_InstanceCreationDate}) put.text(key, series.date);
    for (const DcmTagKey& key : {DCM_SeriesTime, DCM_ContentTime, DCM_InstanceCreationTime}) put.text(key, series.time);
  }
  put.text(DCM_ImageType, "DERIVED\\SECONDARY\\AXIAL");
  put.text(DCM_DerivationDescription, series.derivation);
  put.text(DCM_Manufacturer, "VoxBreast");
  put.text(DCM_SoftwareVersions, config::version);
  put.text(DCM_PositionReferenceIndicator, "");
  put.text(DCM_KVP, "");
  put.text(DCM_AcquisitionNumber, "");
  put.text(DCM_InstanceNumber, std::to_string(k + 1));
  if (!series.source_slices.empty()) {
    const auto [first, last] = series.source_slices[std::size_t(k)];
    for (int source = first; source <= last; ++source) {
      DatasetWriter reference(put.item(DCM_SourceImageSequence), path);
      reference.text(DCM_ReferencedSOPClassUID, series.source_sop_class);
      reference.text(DCM_ReferencedSOPInstanceUID, series.source_instances[std::size_t(source)]);
      DatasetWriter purpose(reference.item(DCM_PurposeOfReferenceCodeSequence), path);
      purpose.text(DCM_CodeValue, "121322");
      purpose.text(DCM_CodingSchemeDesignator, "DCM");
      purpose.text(DCM_CodeMeaning, "Source image for image processing operation");
    }
  }

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
  put.text(DCM_WindowCenter, "40");  // a soft-tissue window: the breast's fat and gland apart
  put.text(DCM_WindowWidth, "400");
  put.text(DCM_WindowCenterWidthExplanation, "SOFT TISSUE");
  const std::size_t slice_voxels = std::size_t(ct.dims[0]) * std::size_t(ct.dims[1]);
  put.words(DCM_PixelData,
            stored_pixels(&ct.values[ct.linear_index(0, 0, k)], slice_voxels, series.rescale));

  errno = 0;
  const OFCondition status = file.saveFile(path.c_str(), EXS_LittleEndianExplicit);
  const int error = errno;  // DCMTK's text does not say why the stream failed; errno does
  require(status.good(),
          std::string("cannot write DICOM file: ") + status.text() + (error ? ": " + system_reason(error) : ""), path);
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

std::vector<std::string> split_values(const std::string& text) {
  std::vector<std::string> values;
  std::size_t begin = 0;
  while (!text.empty()) {
    const std::size_t end = text.find('\\', begin);
    values.push_back(text.substr(begin, end - begin));
    if (end == std::string::npos) break;
    begin = end + 1;
  }
  return values;
}

/// The new series' attributes: geometry, rescale, carried patient and study, UIDs, references.
SeriesAttributes series_attributes(const ImageVolume& ct, const std::string& dir, const DicomSeriesOptions& options) {
  SeriesAttributes series;
  series.geometry = write_geometry(ct, dir);
  series.rescale = choose_rescale(ct.values, dir);
  const UidSource uid(options.deterministic, ct, options.series_description);
  if (!options.deterministic) std::tie(series.date, series.time) = now_date_time();
  series.carried = carried_attributes(ct, uid, series.date, series.time);
  series.series_uid = uid(SITE_SERIES_UID_ROOT, "/series");
  for (int k = 0; k < ct.dims[2]; ++k)
    series.instance_uids.push_back(uid(SITE_INSTANCE_UID_ROOT, "/instance/" + std::to_string(k)));
  series.series_description = options.series_description;
  series.patient_position = options.patient_position;
  const auto source = ct.dicom_tags.find(kSourceSeriesKey);
  series.derivation = "VoxBreast " + std::string(config::version) + " output" +
                      (source != ct.dicom_tags.end() ? " from series " + source->second : "");
  if (!options.source_slices.empty()) {
    series.source_sop_class = tag_of(ct, kSourceSopClassKey);
    series.source_instances = split_values(tag_of(ct, kSourceInstancesKey));
    require(options.source_slices.size() == std::size_t(ct.dims[2]),
            "source slices are given for " + std::to_string(options.source_slices.size()) + " of " +
                std::to_string(ct.dims[2]) + " slices",
            dir);
    require(!series.source_sop_class.empty() && !series.source_instances.empty(),
            "source slices are given, but the volume was not read from a DICOM series", dir);
    for (const auto& [first, last] : options.source_slices)
      require(0 <= first && first <= last && std::size_t(last) < series.source_instances.size(),
              "source slices " + std::to_string(first) + ".." + std::to_string(last) + " lie outside the source's " +
                  std::to_string(series.source_instances.size()) + " slices",
              dir);
    series.source_slices = options.source_slices;
  }
  return series;
}

WrittenDicomSeries write_slices(const StagingFolder& staging, const ImageVolume& ct, const std::string& dir,
                                const DicomSeriesOptions& options) {
  const SeriesAttributes series = series_attributes(ct, dir, options);
  for (int k = 0; k < ct.dims[2]; ++k)
    write_slice((staging.path() / slice_file_name(k)).string(), series, ct, k);
  WrittenDicomSeries written;
  written.study_uid = series.carried.at(tag_key_text(DCM_StudyInstanceUID));
  written.frame_of_reference_uid = series.carried.at(tag_key_text(DCM_FrameOfReferenceUID));
  written.series_uid = series.series_uid;
  written.sop_class_uid = UID_CTImageStorage;
  written.instance_uids = series.instance_uids;
  written.carried = series.carried;
  return written;
}

DicomSeriesOptions described(const std::string& series_description) {
  DicomSeriesOptions options;
  options.series_description = series_description;
  return options;
}

}  // namespace

std::string dicom_patient_position(const Eigen::Vector3d& gravity_lps) {
  if (gravity_lps.norm() == 0) return "";
  Eigen::Index axis = 0;
  gravity_lps.cwiseAbs().maxCoeff(&axis);
  const bool positive = gravity_lps[axis] > 0;
  switch (axis) {
    case 0: return positive ? "HFDL" : "HFDR";  // towards the patient's left: lying on the left side
    case 1: return positive ? "HFS" : "HFP";    // towards the back: supine
    default: return "";                          // along the body: upright or head down
  }
}

WrittenDicomSeries write_dicom_series(const std::string& dir, const ImageVolume& ct, const DicomSeriesOptions& options) {
  init_dcmtk();
  check_writable(ct, dir);
  StagingFolder staging(clean_output_path(dir));
  WrittenDicomSeries written = write_slices(staging, ct, dir, options);
  staging.commit();
  return written;
}

void write_dicom_series(const std::string& dir, const ImageVolume& ct,
                        const std::string& series_description) {
  write_dicom_series(dir, ct, described(series_description));
}

void write_dicom_deformable_registration(const std::string& path, const ImageVolume& grid,
                                         const std::vector<float>& displacement_lps_m,
                                         const ImageVolume& source, const WrittenDicomSeries& registered) {
  init_dcmtk();
  require(displacement_lps_m.size() == 3 * grid.voxel_count(),
          "displacement has " + std::to_string(displacement_lps_m.size()) + " floats for " +
              std::to_string(grid.voxel_count()) + " voxels (3 per voxel expected)",
          path);
  const auto finite = std::find_if(displacement_lps_m.begin(), displacement_lps_m.end(), [](float v) { return !std::isfinite(v); });
  require(finite == displacement_lps_m.end(),
          "the displacement is not finite at voxel " + std::to_string((finite - displacement_lps_m.begin()) / 3), path);
  const WriteGeometry g = write_geometry(grid, path);
  const auto tag = [&](const char* key) { return tag_of(source, key); };
  const std::vector<std::string> source_instances = split_values(tag(kSourceInstancesKey));
  std::string source_frame = tag(tag_key_text(DCM_FrameOfReferenceUID).c_str());
  if (source_frame.empty()) source_frame = registered.frame_of_reference_uid;  // not from DICOM: same patient frame
  const auto [date, time] = now_date_time();

  DcmFileFormat file;
  DatasetWriter put(*file.getDataset(), path);
  put_patient_and_study(put, registered.carried);
  put.text(DCM_SOPClassUID, UID_DeformableSpatialRegistrationStorage);
  put.text(DCM_SOPInstanceUID, new_uid(SITE_INSTANCE_UID_ROOT));
  put.text(DCM_SeriesInstanceUID, new_uid(SITE_SERIES_UID_ROOT));
  put.text(DCM_Modality, "REG");
  put.text(DCM_SeriesNumber, "9001");
  put.text(DCM_SeriesDescription, "VoxBreast deformation");
  put.text(DCM_Laterality, "");
  put.text(DCM_SeriesDate, date);
  put.text(DCM_SeriesTime, time);
  put.text(DCM_InstanceCreationDate, date);
  put.text(DCM_InstanceCreationTime, time);
  put.text(DCM_PositionReferenceIndicator, "");
  put.text(DCM_Manufacturer, "VoxBreast");
  put.text(DCM_ManufacturerModelName, "VoxBreast");
  put.text(DCM_DeviceSerialNumber, config::git_commit);
  put.text(DCM_SoftwareVersions, config::version);
  // Content: the deformation, from the registered frame (the warped CT) into the source CT.
  put.text(DCM_ContentDate, date);
  put.text(DCM_ContentTime, time);
  put.text(DCM_InstanceNumber, "1");
  put.text(DCM_ContentLabel, "DVF_INVERSE");
  put.text(DCM_ContentDescription, "Simulated deformation: source CT at y + d(y) = warped CT");  // LO: 64 characters
  put.text(DCM_ContentCreatorName, "");
  DatasetWriter registration(put.item(DCM_DeformableRegistrationSequence), path);
  registration.text(DCM_SourceFrameOfReferenceUID, source_frame);
  for (const std::string& instance : source_instances) {
    DatasetWriter reference(registration.item(DCM_ReferencedImageSequence), path);
    reference.text(DCM_ReferencedSOPClassUID, tag(kSourceSopClassKey));
    reference.text(DCM_ReferencedSOPInstanceUID, instance);
  }
  registration.text(DCM_FrameOfReferenceTransformationComment,
                    "VoxBreast " + std::string(config::version) + " biomechanical simulation (dvf_inverse)");
  registration.empty_sequence(DCM_RegistrationTypeCodeSequence);
  DcmItem& grid_item = registration.item(DCM_DeformableRegistrationGridSequence);
  DatasetWriter put_grid(grid_item, path);
  Eigen::Matrix<double, 6, 1> cosines;
  cosines << g.row_direction, g.column_direction;
  put_grid.text(DCM_ImagePositionPatient, ds_list(g.origin_mm));
  put_grid.text(DCM_ImageOrientationPatient, ds_list(cosines));
  put_grid.longs(DCM_GridDimensions, {Uint32(grid.dims[0]), Uint32(grid.dims[1]), Uint32(grid.dims[2])});
  put_grid.doubles(DCM_GridResolution, {g.column_spacing_mm, g.row_spacing_mm, g.slice_step_mm.norm()});
  // The vectors in mm go to a temporary file beside `path` in blocks, and DCMTK copies them from
  // there into the file it writes: no second copy of the field is held (it is 12 bytes a voxel).
  const std::string vectors_file = path + ".vectors.tmp";
  struct RemoveOnExit {
    std::string file;
    ~RemoveOnExit() { std::remove(file.c_str()); }
  } remove_vectors{vectors_file};
  {
    std::FILE* out = std::fopen(vectors_file.c_str(), "wb");
    require(out != nullptr, "cannot create a temporary file", vectors_file, "check the folder and its permissions");
    std::vector<Float32> block;
    bool ok = true;
    constexpr std::size_t kBlockFloats = std::size_t(1) << 18;
    for (std::size_t first = 0; ok && first < displacement_lps_m.size(); first += kBlockFloats) {
      const std::size_t count = std::min(kBlockFloats, displacement_lps_m.size() - first);
      block.resize(count);
      for (std::size_t n = 0; n < count; ++n) block[n] = Float32(1e3 * double(displacement_lps_m[first + n]));
      static_assert(std::endian::native == std::endian::little, "the file is read as little-endian");
      ok = std::fwrite(block.data(), sizeof(Float32), count, out) == count;
    }
    ok = std::fclose(out) == 0 && ok;
    require(ok, "cannot write a temporary file", vectors_file, "check free disk space");
  }
  put_grid.floats_from_file(DCM_VectorGridData, vectors_file, sizeof(Float32) * displacement_lps_m.size());
  // Common Instance Reference: the source's series and the warped CT's.
  if (!source_instances.empty()) {
    DatasetWriter series(put.item(DCM_ReferencedSeriesSequence), path);
    series.text(DCM_SeriesInstanceUID, tag(kSourceSeriesKey));
    for (const std::string& instance : source_instances) {
      DatasetWriter reference(series.item(DCM_ReferencedInstanceSequence), path);
      reference.text(DCM_ReferencedSOPClassUID, tag(kSourceSopClassKey));
      reference.text(DCM_ReferencedSOPInstanceUID, instance);
    }
  }
  DatasetWriter warped(put.item(DCM_ReferencedSeriesSequence), path);
  warped.text(DCM_SeriesInstanceUID, registered.series_uid);
  for (const std::string& instance : registered.instance_uids) {
    DatasetWriter reference(warped.item(DCM_ReferencedInstanceSequence), path);
    reference.text(DCM_ReferencedSOPClassUID, registered.sop_class_uid);
    reference.text(DCM_ReferencedSOPInstanceUID, instance);
  }

  AtomicOutput output(path);
  const OFCondition status = file.saveFile(output.temp_path().c_str(), EXS_LittleEndianExplicit);
  require(status.good(), std::string("cannot write DICOM file: ") + status.text(), path);
  output.commit();
}

void check_dicom_series_replaceable(const std::string& dir) { check_own_series_folder(normal_output_path(dir), dir); }

void replace_dicom_series(const std::string& dir, const ImageVolume& ct,
                          const std::string& series_description) {
  replace_dicom_series(dir, ct, described(series_description));
}

WrittenDicomSeries replace_dicom_series(const std::string& dir, const ImageVolume& ct,
                                        const DicomSeriesOptions& options) {
  init_dcmtk();
  check_writable(ct, dir);
  const fs::path final_dir = normal_output_path(dir);
  const bool earlier = check_own_series_folder(final_dir, dir);
  ensure_output_dir(final_dir.parent_path().string());
  StagingFolder staging(final_dir);
  WrittenDicomSeries written = write_slices(staging, ct, dir, options);
  if (!earlier) {
    staging.commit();
    return written;
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
  return written;
}

/// A name-based (SHA-1, version 5) UUID of `name` as a DICOM UID under the 2.25 root
/// (PS3.5 B.2): the same name always gives the same UID.
std::string dicom::name_based_uid(const std::string& name) {
  // RFC 4122 version 5 in VoxBreast's own namespace (a fixed random UUID).
  static const unsigned char kNamespace[16] = {0x3c, 0x8e, 0x52, 0x0b, 0x9d, 0x41, 0x4f, 0x6a,
                                               0xa7, 0x1e, 0x0c, 0x55, 0xd2, 0x93, 0x68, 0xf4};
  Digest sha1(EVP_sha1());
  sha1.add(kNamespace, sizeof kNamespace);
  sha1.add(name.data(), name.size());
  const std::string digest = sha1.finish();
  OFUUID::BinaryRepresentation bytes;
  std::copy(digest.begin(), digest.begin() + 16, bytes.value);
  bytes.value[6] = Uint8((bytes.value[6] & 0x0f) | 0x50);  // version 5
  bytes.value[8] = Uint8((bytes.value[8] & 0x3f) | 0x80);  // RFC 4122 variant
  OFString text;
  return OFUUID(bytes).toString(text, OFUUID::ER_RepresentationOID).c_str();
}

}  // namespace vb
