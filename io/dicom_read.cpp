// Reading a DICOM CT series (io/dicom_io.hpp): the folder's files grouped by series, the slices
// sorted into a regular stack, their pixels decoded into one volume.
#include <dcmtk/config/osconfig.h>  // DCMTK: must come before its other headers
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcmetinf.h>
#include <dcmtk/dcmdata/dcuid.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <new>
#include <optional>

#include "engine/error.hpp"
#include "io/dicom_attributes.hpp"
#include "io/dicom_deflate.hpp"
#include "io/dicom_io.hpp"
#include "io/dicom_pixels.hpp"

namespace fs = std::filesystem;

namespace vb {
using namespace dicom;
namespace {

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

void carry_tags(DcmDataset& data, ImageVolume& volume) {
  for (const DcmTagKey& key : kCarriedTags) {
    OFString value;
    if (data.findAndGetOFStringArray(key, value).good())
      volume.dicom_tags[tag_key_text(key)] = value.c_str();
  }
  volume.dicom_tags[kSourceSeriesKey] = get_text(data, DCM_SeriesInstanceUID);
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
  volume.dicom_tags[kSourceSopClassKey] = get_text(stack.files.front()->data(), DCM_SOPClassUID);
  std::string instances;
  for (const DicomHeader* file : stack.files)
    instances += (instances.empty() ? "" : "\\") + get_text(file->data(), DCM_SOPInstanceUID);
  volume.dicom_tags[kSourceInstancesKey] = instances;
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

}  // namespace vb
