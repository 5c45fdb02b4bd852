#pragma once
/// RT Structure Set files (RTSTRUCT) ↔ StructureSet, through DCMTK's dcmrt (docs/FORMATS.md,
/// "RTSTRUCT"). Contour coordinates are DICOM LPS millimetres in the file, metres inside.
#include <string>

#include "engine/image/structure_set.hpp"

namespace vb {

/// Reads the ROIs (number, name, colour, frame of reference) and their contours. Throws vb::Error
/// naming the file for a file that is not an RTSTRUCT, and naming the ROI for a malformed contour
/// (a geometric type other than CLOSED_PLANAR, a Contour Data count that is not 3 × Number of
/// Contour Points) or a contour naming an ROI number the file does not define.
StructureSet read_rtstruct(const std::string& path);

/// Writes `set` as an RTSTRUCT referencing the CT series in `ct_series_dir` (its patient, study,
/// frame of reference, series and every image; read from its files), with a new series and
/// instance UID (deterministic: UIDs named after the referenced series and `label`, and no
/// structure set date or time, so the same input gives the same bytes). The file appears
/// atomically.
void write_rtstruct(const std::string& path, const StructureSet& set, const std::string& ct_series_dir,
                    const std::string& label, bool deterministic = false);

}  // namespace vb
