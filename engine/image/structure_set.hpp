#pragma once
/// Structures as planar contours (an RTSTRUCT's content, without DICOM) and their conversion
/// to and from label maps on a CT grid (docs/FORMATS.md, "RTSTRUCT").
///
/// Rasterising: a voxel belongs to an ROI when its centre lies inside the ROI's contours on its
/// slice by the even-odd rule (a contour inside another of the same ROI on the same slice is a
/// hole). Partial voxels are decided by their centre alone. Contouring is the exact inverse: the
/// contours of a label run along voxel edges, so rasterising them gives the label map back.
#include <Eigen/Core>
#include <array>
#include <map>
#include <string>
#include <vector>

#include "engine/image/image_volume.hpp"

namespace vb {

struct StructureRoi {
  int number = 0;                                      ///< ROI Number
  std::string name;                                    ///< ROI Name
  std::array<int, 3> color{255, 0, 0};                 ///< ROI Display Color (RGB)
  std::string frame_of_reference_uid;                  ///< Referenced Frame of Reference UID ("" unknown)
  std::vector<std::vector<Eigen::Vector3d>> contours;  ///< closed planar polygons (LPS m), not repeating the first point
};

struct StructureSet {
  std::vector<StructureRoi> rois;
};

/// How ROIs become labels: ROI name → label value (> 0), and, for voxels inside several ROIs, the
/// ROI names in order of precedence (first wins). ROIs absent from `labels` are an error.
struct StructureLabelRule {
  std::map<std::string, int> labels;
  std::vector<std::string> priority;
};

/// Label map on `grid` (values: label numbers, 0 outside every ROI; modality "LABEL").
/// Throws vb::Error naming the ROI for: an ROI's frame of reference other than the grid's
/// (grid.dicom_tags["0020,0052"], when both are known), an ROI with no label, a contour with
/// fewer than 3 points, non-finite points, or points not in one slice plane (farther than a
/// tenth of the slice spacing apart along the slice normal), a contour outside the image (a
/// point more than half a voxel beyond the grid), and voxels inside two ROIs that the priority
/// list does not rank (both must be listed).
ImageVolume rasterise_structures(const StructureSet& set, const ImageVolume& grid, const StructureLabelRule& rule);

/// The contours of the voxels of `labels` equal to `value`, slice by slice, along voxel edges
/// (LPS m), collinear corners dropped; rasterise_structures gives back exactly those voxels.
std::vector<std::vector<Eigen::Vector3d>> contours_of_label(const ImageVolume& labels, int value);

/// One ROI per named label value of `labels` (ROI number = the value), its contours from
/// contours_of_label, distinct display colours; labels with no voxels get no contours.
StructureSet structures_of_labels(const ImageVolume& labels, const std::map<int, std::string>& names);

}  // namespace vb
