#pragma once
/// DICOM CT series ↔ ImageVolume (DICOM LPS patient coordinates; metres inside, mm in the files).
/// Reading sorts slices by their position along the slice normal and checks the stack is a
/// regular grid; writing produces a new CT series in the source's study. Rules: docs/FORMATS.md.
#include <string>
#include <vector>

#include "engine/image/image_volume.hpp"

namespace vb {

/// One series found in a folder.
struct DicomSeriesInfo {
  std::string series_uid, modality, description;
  int files = 0;
};

/// The series of the DICOM files directly in `dir` (not recursive), sorted by UID; empty when there
/// are none. Files that are not DICOM are skipped silently; a DICOM file that cannot be parsed
/// (truncated, corrupt) is a vb::Error naming it.
std::vector<DicomSeriesInfo> list_dicom_series(const std::string& dir);

struct DicomReadOptions {
  /// which series to read; may be empty when the folder holds exactly one
  std::string series_uid;
  /// read a stack with uneven slice gaps (e.g. a missing slice) using the median gap; every
  /// slice beyond a gap is then misplaced by the gap's excess, which is reported as a warning
  bool allow_gaps = false;
  /// read series whose Modality is not CT (values are still stored × slope + intercept)
  bool accept_any_modality = false;
};

/// Reads one series into a volume: i along a row (DICOM column index), j down the columns (row
/// index), k along the slice normal (row direction × column direction), values rescaled to HU.
/// A single slice takes SpacingBetweenSlices (else SliceThickness) as its k spacing.
/// Patient/study attributes go to `dicom_tags` ("gggg,eeee" → text), the series UID to
/// dicom_tags["source_series_uid"], the Modality to `modality`. Warnings (only with allow_gaps)
/// are appended to `*warnings` when given. Throws vb::Error naming the file or the problem.
ImageVolume read_dicom_series(const std::string& dir, const DicomReadOptions& options,
                              std::vector<std::string>* warnings = nullptr);

/// Convenience form of the above for CT series.
ImageVolume read_dicom_series(const std::string& dir, const std::string& series_uid = "",
                              bool allow_gaps = false,
                              std::vector<std::string>* warnings = nullptr);

/// Writes `ct` (HU) as a new CT Image Storage series into `dir`, one file per k slice, Explicit VR
/// Little Endian, signed 16-bit pixels. HU are rounded to integers and stored with slope 1 and
/// intercept −1024 when they fit, else with a slope/intercept spanning [min, max]. New series and
/// instance UIDs; patient/study attributes from `ct.dicom_tags` (defaults when absent). The affine
/// may be oblique or left-handed but not sheared. `dir` must not exist or be empty; the series
/// appears at once (written in a hidden sibling folder, then renamed).
void write_dicom_series(const std::string& dir, const ImageVolume& ct,
                        const std::string& series_description);

/// As write_dicom_series, but `dir` may also hold an earlier series of this writer (only files
/// named CT00001.dcm, CT00002.dcm, …), which the new series replaces whole: it is written beside
/// it and swapped in by two renames, so `dir` never holds slices of both. A folder holding
/// anything else is refused, unchanged. Run outputs (`warped_ct_dicom/`, the phantom's `dicom/`)
/// use this, so a rerun into the same output folder replaces its own series.
void replace_dicom_series(const std::string& dir, const ImageVolume& ct,
                          const std::string& series_description);

/// Throws the error replace_dicom_series would throw for `dir`'s contents, so a command can
/// refuse before it computes anything.
void check_dicom_series_replaceable(const std::string& dir);

}  // namespace vb
