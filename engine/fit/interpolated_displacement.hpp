#pragma once
/// A posture change sampled anywhere near the body: each element's displacement at its voxel
/// centre, extended a few voxel rings past the body (the mean of known face neighbours, so the
/// interpolation at the surface does not pull towards zero) and interpolated trilinearly. The
/// synthetic observations of a validation (deformed label maps and surfaces) move with it.
#include <Eigen/Core>
#include <vector>

#include "engine/lattice/lattice.hpp"

namespace vb {

class InterpolatedDisplacement {
 public:
  /// `change_m`: n×3 per element (world, m); `passes`: rings of empty voxels filled around the body
  InterpolatedDisplacement(const Lattice& lattice, const std::vector<double>& change_m, int passes);
  /// the displacement (world, m) at a point given in lattice index coordinates (voxel centres at
  /// integers); points past the grid take the border's value
  Eigen::Vector3d at_index(const Eigen::Vector3d& ijk) const;

 private:
  std::array<int, 3> dims_;
  std::vector<double> u_;  ///< 3 per lattice voxel
};

}  // namespace vb
