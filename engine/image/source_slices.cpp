#include "engine/image/source_slices.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "engine/error.hpp"

namespace vb {

std::vector<std::pair<int, int>> source_slices_read(const ImageVolume& grid, const std::vector<float>& d) {
  require(d.size() == 3 * grid.voxel_count(), "the field does not match the grid");
  const int nx = grid.dims[0], ny = grid.dims[1], nz = grid.dims[2];
  // The k index of y + d(y) is k + (row 2 of A⁻¹) · d(y): only d's part along that row moves it.
  const Eigen::RowVector3d k_per_m = grid.affine_lps_m.topLeftCorner<3, 3>().inverse().row(2);
  std::vector<std::pair<int, int>> slices(static_cast<std::size_t>(nz));
  std::size_t v = 0;
  for (int k = 0; k < nz; ++k) {
    double low = k, high = k;
    for (int n = 0; n < nx * ny; ++n, ++v) {
      const double at = k + k_per_m.dot(Eigen::Vector3d(d[3 * v], d[3 * v + 1], d[3 * v + 2]));
      low = std::min(low, at);
      high = std::max(high, at);
    }
    const auto clamp = [&](double index) { return std::clamp(int(index), 0, nz - 1); };
    slices[std::size_t(k)] = {clamp(std::floor(low)), clamp(std::ceil(high))};
  }
  return slices;
}

}  // namespace vb
