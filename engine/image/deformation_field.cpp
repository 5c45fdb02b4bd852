#include "engine/image/deformation_field.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <tuple>

#include "engine/error.hpp"

namespace vb {

LatticeField::LatticeField(const Lattice& lattice, const std::vector<double>& u_world)
    : lattice_(lattice), u_(u_world) {
  require(u_world.size() == 3 * lattice.element_count(), "displacement size does not match the model");
}

Eigen::Vector3d LatticeField::lattice_coordinates(const Eigen::Vector3d& p) const {
  return lattice_.rotation.transpose() * (p - lattice_.origin_m) / lattice_.spacing_m;
}

std::int64_t LatticeField::element_of(int i, int j, int k) const {
  const auto& d = lattice_.dims;
  if (i < 0 || j < 0 || k < 0 || i >= d[0] || j >= d[1] || k >= d[2]) return -1;
  return lattice_.element_of_voxel[std::size_t(i) + std::size_t(d[0]) * (std::size_t(j) + std::size_t(d[1]) * k)];
}

std::int64_t LatticeField::element_at(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d q = lattice_coordinates(p);
  return element_of(int(std::lround(q[0])), int(std::lround(q[1])), int(std::lround(q[2])));
}

Eigen::Vector3d LatticeField::displacement_at(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d q = lattice_coordinates(p);
  if (element_of(int(std::lround(q[0])), int(std::lround(q[1])), int(std::lround(q[2]))) < 0)
    return Eigen::Vector3d::Zero();
  const Eigen::Vector3d base = q.array().floor();
  const Eigen::Vector3d f = q - base;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double weight = 0;
  for (int c = 0; c < 8; ++c) {
    const int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
    const std::int64_t e = element_of(int(base[0]) + di, int(base[1]) + dj, int(base[2]) + dk);
    if (e < 0) continue;
    const double w = (di ? f[0] : 1 - f[0]) * (dj ? f[1] : 1 - f[1]) * (dk ? f[2] : 1 - f[2]);
    sum += w * Eigen::Vector3d(u_[3 * e], u_[3 * e + 1], u_[3 * e + 2]);
    weight += w;
  }
  return weight > 0 ? Eigen::Vector3d(sum / weight) : Eigen::Vector3d::Zero();
}

namespace {

/// Calls f(i, j, k, world centre) for every voxel of the grid.
template <class F>
void for_each_voxel(const ImageVolume& grid, F&& f) {
  for (int k = 0; k < grid.dims[2]; ++k)
    for (int j = 0; j < grid.dims[1]; ++j)
      for (int i = 0; i < grid.dims[0]; ++i) f(i, j, k, grid.world_of_index(Eigen::Vector3d(i, j, k)));
}

/// Trilinear sample of the image at continuous index q; edge voxels extend outwards.
float sample(const ImageVolume& img, const Eigen::Vector3d& q) {
  const Eigen::Vector3d c = q.cwiseMax(Eigen::Vector3d::Zero())
                                .cwiseMin(Eigen::Vector3d(img.dims[0] - 1, img.dims[1] - 1, img.dims[2] - 1));
  const Eigen::Vector3i b(int(std::floor(c[0])), int(std::floor(c[1])), int(std::floor(c[2])));
  const Eigen::Vector3d f = c - b.cast<double>();
  double v = 0;
  for (int n = 0; n < 8; ++n) {
    const int di = n & 1, dj = (n >> 1) & 1, dk = (n >> 2) & 1;
    const int i = std::min(b[0] + di, img.dims[0] - 1), j = std::min(b[1] + dj, img.dims[1] - 1),
              k = std::min(b[2] + dk, img.dims[2] - 1);
    const double w = (di ? f[0] : 1 - f[0]) * (dj ? f[1] : 1 - f[1]) * (dk ? f[2] : 1 - f[2]);
    v += w * img.values[img.linear_index(i, j, k)];
  }
  return float(v);
}

}  // namespace

std::vector<float> forward_displacement_on_grid(const LatticeField& field, const ImageVolume& grid) {
  std::vector<float> out(3 * grid.voxel_count(), 0.f);
  for_each_voxel(grid, [&](int i, int j, int k, const Eigen::Vector3d& p) {
    const Eigen::Vector3d u = field.displacement_at(p);
    const std::size_t v = grid.linear_index(i, j, k);
    for (int c = 0; c < 3; ++c) out[3 * v + c] = float(u[c]);
  });
  return out;
}

namespace {

/// Where tissue ends up: for each CT voxel, the displacement of an element whose displaced centre
/// lies in it (the starting guesses for inverting x + u(x) = y near moved tissue).
std::vector<std::int64_t> splat_elements(const ImageVolume& ct, const Lattice& lattice, const std::vector<double>& u) {
  std::vector<std::int64_t> seed(ct.voxel_count(), -1);
  const Eigen::Matrix4d to_index = ct.affine_lps_m.inverse();
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    const Eigen::Vector3d y = lattice.rest_position(e) + Eigen::Vector3d(u[3 * e], u[3 * e + 1], u[3 * e + 2]);
    const Eigen::Vector3d q = (to_index * y.homogeneous()).head<3>();
    const int i = int(std::lround(q[0])), j = int(std::lround(q[1])), k = int(std::lround(q[2]));
    if (i < 0 || j < 0 || k < 0 || i >= ct.dims[0] || j >= ct.dims[1] || k >= ct.dims[2]) continue;
    seed[ct.linear_index(i, j, k)] = std::int64_t(e);
  }
  return seed;
}

}  // namespace

WarpResult warp_image(const ImageVolume& ct, const Lattice& lattice, const std::vector<double>& u, int iterations) {
  const LatticeField field(lattice, u);
  WarpResult r;
  r.warped = ct;
  r.inverse_field.assign(3 * ct.voxel_count(), 0.f);
  const Eigen::Matrix4d to_index = ct.affine_lps_m.inverse();
  const std::vector<std::int64_t> seed = splat_elements(ct, lattice, u);
  const float background = *std::min_element(ct.values.begin(), ct.values.end());
  const double tolerance = 1e-3 * ct.spacing_m().minCoeff();
  // Search radius for seeds: lattice elements can be sparser than CT voxels.
  const int reach = 1 + int(std::ceil(lattice.spacing_m / ct.spacing_m().minCoeff()));
  // A tissue point x (inside the model) with x + u(x) = y, tried from y and from nearby seeds.
  auto tissue_source = [&](const Eigen::Vector3d& y, Eigen::Vector3d x, Eigen::Vector3d& found) {
    for (int it = 0; it < iterations; ++it) x = y - field.displacement_at(x);
    const double residual = (x + field.displacement_at(x) - y).norm();
    if (residual > tolerance || field.element_at(x) < 0) return false;
    r.max_fixed_point_residual_m = std::max(r.max_fixed_point_residual_m, residual);
    found = x;
    return true;
  };
  for_each_voxel(ct, [&](int i, int j, int k, const Eigen::Vector3d& y) {
    const std::size_t v = ct.linear_index(i, j, k);
    Eigen::Vector3d x;
    bool found = tissue_source(y, y, x);
    for (int dk = -reach; dk <= reach && !found; ++dk)
      for (int dj = -reach; dj <= reach && !found; ++dj)
        for (int di = -reach; di <= reach && !found; ++di) {
          const int a = i + di, b = j + dj, c = k + dk;
          if (a < 0 || b < 0 || c < 0 || a >= ct.dims[0] || b >= ct.dims[1] || c >= ct.dims[2]) continue;
          const std::int64_t e = seed[ct.linear_index(a, b, c)];
          if (e >= 0) found = tissue_source(y, y - Eigen::Vector3d(u[3 * e], u[3 * e + 1], u[3 * e + 2]), x);
        }
    if (found) {
      r.warped.values[v] = sample(ct, (to_index * x.homogeneous()).head<3>());
      for (int c = 0; c < 3; ++c) r.inverse_field[3 * v + c] = float(x[c] - y[c]);
    } else if (field.element_at(y) >= 0) {  // tissue left this voxel and none arrived
      r.warped.values[v] = background;
      ++r.vacated_voxels;
    }  // else: background that no tissue reaches keeps its value
  });
  return r;
}

ImageVolume rasterise_elements(const LatticeField& field, const ImageVolume& grid, const std::vector<double>& values,
                               float outside) {
  ImageVolume out;
  out.dims = grid.dims;
  out.affine_lps_m = grid.affine_lps_m;
  out.values.assign(grid.voxel_count(), outside);
  for_each_voxel(grid, [&](int i, int j, int k, const Eigen::Vector3d& p) {
    const std::int64_t e = field.element_at(p);
    if (e >= 0) out.values[grid.linear_index(i, j, k)] = float(values[std::size_t(e)]);
  });
  return out;
}

}  // namespace vb
