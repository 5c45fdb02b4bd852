#pragma once
/// Signed distance to the boundary of a region of a voxel image (docs/FIT.md, "Observation from a
/// label map"): an exact separable Euclidean distance transform (Felzenszwalb & Huttenlocher 2012)
/// on the host, sampled trilinearly at world points.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/image/image_volume.hpp"

namespace vb {

/// Squared Euclidean distance (m²) from every voxel centre to the nearest voxel centre where
/// `feature` is non-zero, on a grid of `dims` with per-axis `spacing_m` (orthogonal axes);
/// +inf everywhere when there is no feature voxel.
std::vector<double> squared_distance_transform(const std::vector<std::uint8_t>& feature, const std::array<int, 3>& dims,
                                               const Eigen::Vector3d& spacing_m);

/// A signed distance to an observed surface (negative inside), at world points (LPS m): from a
/// label map (SignedDistanceField) or a triangle mesh (MeshSignedDistance, mesh_distance.hpp).
class SurfaceDistance {
 public:
  virtual ~SurfaceDistance() = default;
  virtual double at(const Eigen::Vector3d& p_m) const = 0;
};

/// A signed distance field on an image's grid: negative inside the region, positive outside, zero
/// on the voxel faces between them (each voxel centre's distance to the nearest centre on the
/// other side, less half the smallest spacing).
class SignedDistanceField final : public SurfaceDistance {
 public:
  /// `inside`: one flag per voxel of `grid` (its values are not read). Throws vb::Error when the
  /// region is empty or fills the whole grid (no boundary), naming `what`.
  SignedDistanceField(const ImageVolume& grid, const std::vector<std::uint8_t>& inside, const std::string& what);
  /// trilinear at a world point (LPS m); points outside the grid take the nearest border value
  double at(const Eigen::Vector3d& p_m) const override;

 private:
  std::array<int, 3> dims_;
  Eigen::Matrix4d to_index_;
  std::vector<float> phi_m_;
};

}  // namespace vb
