// Writing a DICOM CT series (io/dicom_io.hpp): one file per slice, staged in a hidden sibling
// folder and renamed into place.
#include <dcmtk/config/osconfig.h>  // DCMTK: must come before its other headers
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcuid.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>

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
