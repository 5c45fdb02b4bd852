#include "engine/fit/interpolated_displacement.hpp"

#include <algorithm>
#include <cmath>

namespace vb {

InterpolatedDisplacement::InterpolatedDisplacement(const Lattice& lat, const std::vector<double>& change_m, int passes)
    : dims_(lat.dims) {
  const std::size_t count = std::size_t(lat.dims[0]) * lat.dims[1] * lat.dims[2];
  u_.assign(3 * count, 0.0);
  std::vector<std::uint8_t> known(count, 0);
  for (std::size_t e = 0; e < lat.element_count(); ++e) {
    const std::size_t v = lat.voxel_of_element[e];
    for (int a = 0; a < 3; ++a) u_[3 * v + a] = change_m[3 * e + a];
    known[v] = 1;
  }
  const int nx = lat.dims[0], ny = lat.dims[1], nz = lat.dims[2];
  for (int pass = 0; pass < passes; ++pass) {
    std::vector<std::uint8_t> next = known;
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const std::size_t v = std::size_t(i) + std::size_t(nx) * (std::size_t(j) + std::size_t(ny) * k);
          if (known[v]) continue;
          double sum[3] = {0, 0, 0};
          int n = 0;
          for (int d = 0; d < 6; ++d) {
            const auto& o = neighbour_offsets()[std::size_t(d)];
            const int a = i + o[0], b = j + o[1], c = k + o[2];
            if (a < 0 || b < 0 || c < 0 || a >= nx || b >= ny || c >= nz) continue;
            const std::size_t w = std::size_t(a) + std::size_t(nx) * (std::size_t(b) + std::size_t(ny) * c);
            if (!known[w]) continue;
            for (int x = 0; x < 3; ++x) sum[x] += u_[3 * w + x];
            ++n;
          }
          if (n == 0) continue;
          for (int x = 0; x < 3; ++x) u_[3 * v + x] = sum[x] / n;
          next[v] = 1;
        }
    known = std::move(next);
  }
}

Eigen::Vector3d InterpolatedDisplacement::at_index(const Eigen::Vector3d& c) const {
  int base[3];
  double frac[3];
  for (int a = 0; a < 3; ++a) {
    const double q = std::clamp(c[a], 0.0, double(dims_[a] - 1));
    base[a] = std::min(int(std::floor(q)), std::max(0, dims_[a] - 2));
    frac[a] = std::clamp(q - base[a], 0.0, 1.0);
  }
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int corner = 0; corner < 8; ++corner) {
    const int o[3] = {corner & 1, (corner >> 1) & 1, (corner >> 2) & 1};
    double w = 1;
    int ijk[3];
    for (int a = 0; a < 3; ++a) {
      w *= o[a] ? frac[a] : 1 - frac[a];
      ijk[a] = std::min(base[a] + o[a], dims_[a] - 1);
    }
    if (w == 0) continue;
    const std::size_t v = std::size_t(ijk[0]) + std::size_t(dims_[0]) * (std::size_t(ijk[1]) + std::size_t(dims_[1]) * ijk[2]);
    out += w * Eigen::Vector3d(u_[3 * v], u_[3 * v + 1], u_[3 * v + 2]);
  }
  return out;
}

}  // namespace vb
