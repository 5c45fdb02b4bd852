#pragma once
/// A scalar image on a voxel grid with its world affine: the common currency between readers
/// (NIfTI, DICOM), the phantom generator, the lattice builder and the writers (DVF, warped CT).
#include <Eigen/Core>
#include <array>
#include <map>
#include <string>
#include <vector>

namespace vb {

struct ImageVolume {
  std::array<int, 3> dims{0, 0, 0};  ///< voxels along i, j, k
  /// voxel index (i, j, k, 1) → world point in DICOM LPS patient coordinates, metres.
  /// Columns 0..2 are the voxel axes scaled by the spacing (may be oblique), column 3 the
  /// centre of voxel (0, 0, 0).
  Eigen::Matrix4d affine_lps_m = Eigen::Matrix4d::Identity();
  std::vector<float> values;  ///< dims product, i fastest; CT in Hounsfield units after rescale
  std::string modality;       ///< "CT", "LABEL", or "" when unknown
  /// DICOM attributes carried from a source series to derived series (patient/study module),
  /// keyed by tag "gggg,eeee" → value as text. Empty for NIfTI sources.
  std::map<std::string, std::string> dicom_tags;

  std::size_t voxel_count() const { return std::size_t(dims[0]) * dims[1] * dims[2]; }
  std::size_t linear_index(int i, int j, int k) const {
    return std::size_t(i) + std::size_t(dims[0]) * (std::size_t(j) + std::size_t(dims[1]) * std::size_t(k));
  }
  /// spacing along each voxel axis (m)
  Eigen::Vector3d spacing_m() const {
    return {affine_lps_m.block<3, 1>(0, 0).norm(), affine_lps_m.block<3, 1>(0, 1).norm(),
            affine_lps_m.block<3, 1>(0, 2).norm()};
  }
  Eigen::Vector3d world_of_index(const Eigen::Vector3d& ijk) const {
    return affine_lps_m.topLeftCorner<3, 3>() * ijk + affine_lps_m.topRightCorner<3, 1>();
  }
};

}  // namespace vb
