#pragma once
/// DICOM CT series ↔ ImageVolume (DICOM LPS patient coordinates; metres inside, mm in the files).
/// Reading sorts slices by their position along the slice normal and checks the stack is a
/// regular grid; writing produces a new CT series in the source's study. Rules: docs/FORMATS.md.
#include <Eigen/Core>
#include <map>
#include <string>
#include <utility>
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

/// How a written series is identified and what it derives from (docs/FORMATS.md, "Writing").
struct DicomSeriesOptions {
  std::string series_description;
  /// PatientPosition (0018,5100), e.g. "HFS" or "HFP" (dicom_patient_position); "" writes it
  /// empty, DICOM's "unknown".
  std::string patient_position;
  /// UIDs derived from the volume's content (name-based UUIDs under the 2.25 root) and no
  /// dates or times, so the same volume always gives the same files (the bundled phantom);
  /// otherwise fresh UIDs and the time of writing.
  bool deterministic = false;
  /// For each written slice k, the slices [first, last] of the series the volume was read from
  /// (ImageVolume::dicom_tags "source_instance_uids") that its values come from: listed in its
  /// SourceImageSequence. Empty: no SourceImageSequence. A slice range needs those UIDs.
  std::vector<std::pair<int, int>> source_slices;
};

/// What identifies a written series, for objects that reference it.
struct WrittenDicomSeries {
  std::string study_uid, series_uid, frame_of_reference_uid, sop_class_uid;
  std::vector<std::string> instance_uids;  ///< SOPInstanceUID of slice k
  /// the patient, study and frame attributes written ("gggg,eeee" → value), defaults included
  std::map<std::string, std::string> carried;
};

/// PatientPosition (0018,5100) of a patient lying under gravity `gravity_lps` (body frame, any
/// length): head first, and supine (HFS), prone (HFP), on the left side (HFDL) or on the right
/// (HFDR) by the body axis closest to gravity; "" when gravity is zero or runs along the body
/// (upright), which PatientPosition cannot say.
std::string dicom_patient_position(const Eigen::Vector3d& gravity_lps);

/// Writes `ct` (HU) as a new CT Image Storage series into `dir`, one file per k slice, Explicit VR
/// Little Endian, signed 16-bit pixels. HU are rounded to integers and stored with slope 1 and
/// intercept −1024 when they fit, else with a slope/intercept spanning [min, max]. New series and
/// instance UIDs; patient/study attributes from `ct.dicom_tags` (defaults when absent). The affine
/// may be oblique or left-handed but not sheared. `dir` must not exist or be empty; the series
/// appears at once (written in a hidden sibling folder, then renamed).
WrittenDicomSeries write_dicom_series(const std::string& dir, const ImageVolume& ct,
                                      const DicomSeriesOptions& options);
void write_dicom_series(const std::string& dir, const ImageVolume& ct,
                        const std::string& series_description);

/// As write_dicom_series, but `dir` may also hold an earlier series of this writer (only files
/// named CT00001.dcm, CT00002.dcm, …), which the new series replaces whole: it is written beside
/// it and swapped in by two renames, so `dir` never holds slices of both. A folder holding
/// anything else is refused, unchanged. Run outputs (`warped_ct_dicom/`, the phantom's `dicom/`)
/// use this, so a rerun into the same output folder replaces its own series.
WrittenDicomSeries replace_dicom_series(const std::string& dir, const ImageVolume& ct,
                                        const DicomSeriesOptions& options);
void replace_dicom_series(const std::string& dir, const ImageVolume& ct,
                          const std::string& series_description);

/// Writes `path` (one Part 10 file, atomic) as a Deformable Spatial Registration (modality REG)
/// holding the displacement field d on `grid`'s voxels (`displacement_lps_m`: 3 floats, LPS metres,
/// per voxel, i fastest) as its Deformable Registration Grid: the source CT is sampled at y + d(y)
/// for each point y of the registered frame, `registered`'s (the warped CT's) frame of reference.
/// The source is the CT `source` was read from: its frame (or, for a CT not read from DICOM,
/// the registered one), its slices in Referenced Image Sequence; the study, patient and frame
/// are `registered`'s; Common Instance Reference lists the source's and `registered`'s series.
void write_dicom_deformable_registration(const std::string& path, const ImageVolume& grid,
                                         const std::vector<float>& displacement_lps_m,
                                         const ImageVolume& source, const WrittenDicomSeries& registered);

/// Throws the error replace_dicom_series would throw for `dir`'s contents, so a command can
/// refuse before it computes anything.
void check_dicom_series_replaceable(const std::string& dir);

}  // namespace vb
