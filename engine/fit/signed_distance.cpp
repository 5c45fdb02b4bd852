#include "engine/fit/signed_distance.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/error.hpp"

namespace vb {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// 1-D squared distance transform of sampled function f (lower envelope of parabolas), sites
/// `h` apart; f = +inf marks no site. Writes d, uses v and z as scratch (size n and n + 1).
void distance_1d(const double* f, double* d, int n, double h, std::vector<int>& v, std::vector<double>& z) {
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] == kInf) continue;
    const double xq = q * h;
    while (k >= 0) {
      const double xv = v[std::size_t(k)] * h;
      const double s = ((f[q] + xq * xq) - (f[v[std::size_t(k)]] + xv * xv)) / (2 * (xq - xv));
      if (s <= z[std::size_t(k)]) --k;
      else {
        ++k;
        v[std::size_t(k)] = q;
        z[std::size_t(k)] = s;
        z[std::size_t(k) + 1] = kInf;
        break;
      }
    }
    if (k < 0) {
      k = 0;
      v[0] = q;
      z[0] = -kInf;
      z[1] = kInf;
    }
  }
  if (k < 0) {
    std::fill(d, d + n, kInf);
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[std::size_t(j) + 1] < q * h) ++j;
    const double dx = (q - v[std::size_t(j)]) * h;
    d[q] = dx * dx + f[v[std::size_t(j)]];
  }
}

}  // namespace

std::vector<double> squared_distance_transform(const std::vector<std::uint8_t>& feature, const std::array<int, 3>& dims,
                                               const Eigen::Vector3d& spacing) {
  const std::size_t count = std::size_t(dims[0]) * dims[1] * dims[2];
  std::vector<double> g(count);
  for (std::size_t i = 0; i < count; ++i) g[i] = feature[i] ? 0.0 : kInf;
  const int longest = std::max({dims[0], dims[1], dims[2]});
  const std::size_t length = std::size_t(longest);
  std::vector<double> line(length), out(length), z(length + 1);
  std::vector<int> v(length);
  const std::size_t stride[3] = {1, std::size_t(dims[0]), std::size_t(dims[0]) * dims[1]};
  for (int axis = 0; axis < 3; ++axis) {  // separable: one pass per axis over every line
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    for (int j = 0; j < dims[b]; ++j)
      for (int i = 0; i < dims[a]; ++i) {
        const std::size_t base = std::size_t(i) * stride[a] + std::size_t(j) * stride[b];
        for (int q = 0; q < dims[axis]; ++q) line[std::size_t(q)] = g[base + std::size_t(q) * stride[axis]];
        distance_1d(line.data(), out.data(), dims[axis], spacing[axis], v, z);
        for (int q = 0; q < dims[axis]; ++q) g[base + std::size_t(q) * stride[axis]] = out[std::size_t(q)];
      }
  }
  return g;
}

SignedDistanceField::SignedDistanceField(const ImageVolume& grid, const std::vector<std::uint8_t>& inside,
                                         const std::string& what)
    : dims_(grid.dims), to_index_(grid.affine_lps_m.inverse()) {
  const std::size_t count = grid.voxel_count();
  require(inside.size() == count, "region mask does not match its grid", what);
  const std::size_t in = std::size_t(std::count_if(inside.begin(), inside.end(), [](std::uint8_t x) { return x != 0; }));
  require(in > 0, "the observed label map has no voxel of this region", what,
          "check observed_label_values against the label map's values");
  require(in < count, "the region fills the whole observed label map: it has no boundary", what,
          "give a label map whose grid extends past the region");
  // one transform at a time (peak memory: one double per voxel besides the field)
  const Eigen::Vector3d h = grid.spacing_m();
  const double half = 0.5 * h.minCoeff();  // the boundary lies on the faces between voxel centres
  phi_m_.resize(count);
  {
    const std::vector<double> to_inside = squared_distance_transform(inside, dims_, h);
    for (std::size_t i = 0; i < count; ++i)
      if (!inside[i]) phi_m_[i] = float(std::sqrt(to_inside[i]) - half);
  }
  std::vector<std::uint8_t> outside(count);
  for (std::size_t i = 0; i < count; ++i) outside[i] = !inside[i];
  const std::vector<double> to_outside = squared_distance_transform(outside, dims_, h);
  for (std::size_t i = 0; i < count; ++i)
    if (inside[i]) phi_m_[i] = float(-(std::sqrt(to_outside[i]) - half));
}

double SignedDistanceField::at(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d q = (to_index_ * p.homogeneous()).head<3>();
  int base[3];
  double frac[3];
  for (int a = 0; a < 3; ++a) {
    const double c = std::clamp(q[a], 0.0, double(dims_[a] - 1));
    base[a] = std::min(int(std::floor(c)), std::max(0, dims_[a] - 2));
    frac[a] = std::clamp(c - base[a], 0.0, 1.0);
  }
  double sum = 0;
  for (int c = 0; c < 8; ++c) {
    const int o[3] = {c & 1, (c >> 1) & 1, (c >> 2) & 1};
    double w = 1;
    std::size_t idx = 0, stride = 1;
    for (int a = 0; a < 3; ++a) {
      w *= o[a] ? frac[a] : 1 - frac[a];
      idx += std::size_t(std::min(base[a] + o[a], dims_[a] - 1)) * stride;
      stride *= std::size_t(dims_[a]);
    }
    if (w != 0) sum += w * phi_m_[idx];
  }
  return sum;
}

}  // namespace vb
