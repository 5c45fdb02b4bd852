#pragma once
/// Comparing displacement fields of lattices of different resolution at common physical points.
#include <vector>

#include "engine/lattice/lattice.hpp"

namespace vb::bench {

/// Displacement of a lattice field (n×3, m) at world points (m): trilinear interpolation between
/// the 8 element centres of the lattice cell around the point, the weights renormalised over the
/// corners that hold an element. A point beyond the outermost centres is clamped onto the lattice
/// box first (constant extrapolation over at most half a coarse spacing plus the voxel rounding);
/// a point with no occupied corner takes its nearest element's displacement. Exact for constant
/// fields everywhere and for linear fields inside fully occupied cells.
std::vector<Eigen::Vector3d> sample_displacement(const Lattice& lattice, const std::vector<double>& u_m,
                                                 const std::vector<Eigen::Vector3d>& points_m);

struct FieldError {
  double max_m = 0;  ///< largest |u − u_ref| over the points (m)
  double rms_m = 0;  ///< root mean square of |u − u_ref| over the points (m)
};

/// max and RMS of |u − u_ref| over paired samples.
FieldError field_error(const std::vector<Eigen::Vector3d>& u, const std::vector<Eigen::Vector3d>& u_ref);

/// Mean z displacement of the top layer of elements (m): what the column's closed form predicts.
double top_layer_mean_uz(const Lattice& lattice, const std::vector<double>& u_m);

}  // namespace vb::bench
