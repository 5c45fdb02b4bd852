#pragma once
/// The simulated deformation on image grids: the forward displacement field on the CT grid,
/// its inverse, the warped CT (a synthetic second-posture CT), and per-element values
/// rasterised back to the CT grid.
#include <functional>
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

/// Told the fraction of an image's voxels done, in [0, 1], from one thread.
using ImageProgress = std::function<void(double fraction)>;

/// Forward field u on the grid's voxels: tissue at x moves to x + u(x) (LPS m, 3 per voxel).
/// Slices are computed on all the host's cores.
std::vector<float> forward_displacement_on_grid(const LatticeField& field, const ImageVolume& grid,
                                                const ImageProgress& progress = {});

struct WarpResult {
  ImageVolume warped;                 ///< the CT as it looks after the deformation
  std::vector<float> inverse_field;   ///< d(y) = x − y with x + u(x) = y: resampling the input CT
                                      ///< at y + d(y) gives `warped` (ITK's resampling convention)
  double max_fixed_point_residual_m = 0;  ///< worst |x + u(x) − y| of the solved voxels (m)
  std::size_t vacated_voxels = 0;         ///< voxels tissue left and none arrived in
};

/// Warped CT by pulling: for each output voxel y, solve x + u(x) = y by fixed-point iteration
/// (x ← y − u(x), at most `iterations` steps, stopping once |x + u(x) − y| is below a millionth
/// of the smallest CT spacing), starting first from the solution of the previous voxel of the
/// row (the inverse field is smooth, so this start is a step or two from the answer), then from
/// y, then from the displacements of elements that landed near y, nearest first; then sample the
/// CT at x trilinearly. A solution counts when |x + u(x) − y| is within a thousandth of the
/// smallest CT spacing and x lies in the model. Voxels outside the model that no tissue reaches
/// keep their value; voxels tissue left take the CT's lowest value (air). u: n×3 (m, world).
/// Slices are solved on all the host's cores; the result does not depend on their number.
WarpResult warp_image(const ImageVolume& ct, const Lattice& lattice, const std::vector<double>& u,
                      int iterations = 30, const ImageProgress& progress = {});

/// A label map on the CT grid carried along by warp_image's pull: voxel y takes the label of the
/// voxel nearest to its source y + d(y) (`inverse_field`, warp_image's); where d(y) is zero inside
/// the model, the voxel's own fixed point is solved again as warp_image solved it, and a voxel
/// tissue left (no solution) takes label 0; voxels outside the model keep their label. Done
/// after the warp, so the warped CT need not be held with it. Slices on all cores.
ImageVolume warp_labels(const ImageVolume& labels, const Lattice& lattice, const std::vector<double>& u,
                        const std::vector<float>& inverse_field, int iterations = 30,
                        const ImageProgress& progress = {});

/// Per-element values rasterised on the grid: each voxel takes the value of the element
/// containing its centre, `outside` elsewhere. values: n (one per element).
ImageVolume rasterise_elements(const LatticeField& field, const ImageVolume& grid,
                               const std::vector<double>& values, float outside);

/// Calls slice(k) for every slice k of the grid on all the host's cores (slices taken in turn as
/// threads free up), and progress(fraction done) from one thread. slice must not throw.
void for_each_slice(const ImageVolume& grid, const std::function<void(int k)>& slice,
                    const ImageProgress& progress = {});

}  // namespace vb
