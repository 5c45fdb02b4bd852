#pragma once
/// The simulated deformation on image grids: the forward displacement field on the CT grid,
/// its inverse, the warped CT (a synthetic second-posture CT), and per-element values
/// rasterised back to the CT grid.
#include <vector>

#include "engine/image/image_volume.hpp"
#include "engine/lattice/lattice.hpp"

namespace vb {

/// Element displacements as a field over the model's voxel body.
class LatticeField {
 public:
  /// u_world: n×3 element displacements (m, world frame)
  LatticeField(const Lattice& lattice, const std::vector<double>& u_world);

  /// Element whose lattice voxel contains world point p (m), or −1 outside the model.
  std::int64_t element_at(const Eigen::Vector3d& p) const;
  /// Displacement at p (m): trilinear over the 8 surrounding element centres that exist,
  /// renormalised. Zero outside the model's voxel body.
  Eigen::Vector3d displacement_at(const Eigen::Vector3d& p) const;

 private:
  Eigen::Vector3d lattice_coordinates(const Eigen::Vector3d& p) const;
  std::int64_t element_of(int i, int j, int k) const;
  const Lattice& lattice_;
  const std::vector<double>& u_;
};

/// Forward field u on the grid's voxels: tissue at x moves to x + u(x) (LPS m, 3 per voxel).
std::vector<float> forward_displacement_on_grid(const LatticeField& field, const ImageVolume& grid);

struct WarpResult {
  ImageVolume warped;                 ///< the CT as it looks after the deformation
  std::vector<float> inverse_field;   ///< d(y) = x − y with x + u(x) = y: resampling the input CT
                                      ///< at y + d(y) gives `warped` (ITK's resampling convention)
  double max_fixed_point_residual_m = 0;  ///< worst |x + u(x) − y| of the solved voxels (m)
  std::size_t vacated_voxels = 0;         ///< voxels tissue left and none arrived in
};

/// Warped CT by pulling: for each output voxel y, solve x + u(x) = y by fixed-point iteration
/// (x ← y − u(x)), starting from y and from the displacements of elements that landed near y;
/// then sample the CT at x trilinearly. Voxels outside the model that no tissue reaches keep
/// their value; voxels tissue left take the CT's lowest value (air). u: n×3 (m, world).
WarpResult warp_image(const ImageVolume& ct, const Lattice& lattice, const std::vector<double>& u,
                      int iterations = 30);

/// Per-element values rasterised on the grid: each voxel takes the value of the element
/// containing its centre, `outside` elsewhere. values: n (one per element).
ImageVolume rasterise_elements(const LatticeField& field, const ImageVolume& grid,
                               const std::vector<double>& values, float outside);

}  // namespace vb
