#pragma once
/// Summary statistics of a displacement field on an image grid, the ones plastimatch's
/// `plastimatch stats` prints for a vector field, so the two can be compared number for number.
#include <array>
#include <vector>

namespace vb {

/// Over every voxel of the grid (zeros included), components LPS, millimetres.
struct DisplacementStats {
  std::array<double, 3> min_mm{}, max_mm{}, mean_mm{};  ///< per component
  std::array<double, 3> mean_abs_mm{};                  ///< mean of |u_c| per component
  double mean_length_mm = 0;                            ///< mean of |u|
  double max_length_mm = 0;                             ///< largest |u|
};

/// displacement_lps_m: 3 floats (LPS metres) per voxel. An empty field gives all zeros.
DisplacementStats displacement_stats(const std::vector<float>& displacement_lps_m);

}  // namespace vb
