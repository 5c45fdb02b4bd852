#include "engine/fit/deformed_labels.hpp"

#include <Eigen/LU>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace vb {
namespace {

/// The displacement on every lattice voxel: the element's own, then `passes` rings of empty voxels
/// around the body get the mean of their already known face neighbours (so the interpolation
/// near the surface does not pull towards zero).
std::vector<double> extended_field(const Lattice& lat, const std::vector<double>& change_m, int passes) {
  const std::size_t count = std::size_t(lat.dims[0]) * lat.dims[1] * lat.dims[2];
  std::vector<double> u(3 * count, 0.0);
  std::vector<std::uint8_t> known(count, 0);
  for (std::size_t e = 0; e < lat.element_count(); ++e) {
    const std::size_t v = lat.voxel_of_element[e];
    for (int a = 0; a < 3; ++a) u[3 * v + a] = change_m[3 * e + a];
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
            for (int x = 0; x < 3; ++x) sum[x] += u[3 * w + x];
            ++n;
          }
          if (n == 0) continue;
          for (int x = 0; x < 3; ++x) u[3 * v + x] = sum[x] / n;
          next[v] = 1;
        }
    known = std::move(next);
  }
  return u;
}

Eigen::Vector3d sample(const Lattice& lat, const std::vector<double>& u, const Eigen::Vector3d& c) {
  int base[3];
  double frac[3];
  for (int a = 0; a < 3; ++a) {
    const double q = std::clamp(c[a], 0.0, double(lat.dims[a] - 1));
    base[a] = std::min(int(std::floor(q)), std::max(0, lat.dims[a] - 2));
    frac[a] = std::clamp(q - base[a], 0.0, 1.0);
  }
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int corner = 0; corner < 8; ++corner) {
    const int o[3] = {corner & 1, (corner >> 1) & 1, (corner >> 2) & 1};
    double w = 1;
    int ijk[3];
    for (int a = 0; a < 3; ++a) {
      w *= o[a] ? frac[a] : 1 - frac[a];
      ijk[a] = std::min(base[a] + o[a], lat.dims[a] - 1);
    }
    if (w == 0) continue;
    const std::size_t v = std::size_t(ijk[0]) + std::size_t(lat.dims[0]) * (std::size_t(ijk[1]) + std::size_t(lat.dims[1]) * ijk[2]);
    out += w * Eigen::Vector3d(u[3 * v], u[3 * v + 1], u[3 * v + 2]);
  }
  return out;
}

}  // namespace

ImageVolume deformed_label_map(const Lattice& lat, const std::vector<double>& change_m,
                               const std::vector<int>& value_of_tissue, int subdivide) {
  double largest = 0;
  for (std::size_t e = 0; e < lat.element_count(); ++e)
    largest = std::max(largest, std::hypot(change_m[3 * e], change_m[3 * e + 1], change_m[3 * e + 2]));
  const int s = std::max(1, subdivide);
  const int margin = int(std::ceil(largest / lat.spacing_m * s)) + 2;  // fine voxels past the lattice
  const int passes = int(std::ceil(largest / lat.spacing_m)) + 2;
  const std::vector<double> u = extended_field(lat, change_m, passes);

  // fine voxel f ↦ lattice index −½ + (f − margin + ½)/s: s fine voxels tile one lattice voxel
  const Eigen::Matrix4d A = lat.affine();
  Eigen::Matrix4d fine_to_lattice = Eigen::Matrix4d::Identity();
  fine_to_lattice.topLeftCorner<3, 3>() /= s;
  fine_to_lattice.topRightCorner<3, 1>().setConstant(-0.5 + (0.5 - margin) / s);
  ImageVolume out;
  out.modality = "LABEL";
  out.affine_lps_m = A * fine_to_lattice;
  for (int a = 0; a < 3; ++a) out.dims[a] = lat.dims[a] * s + 2 * margin;
  out.values.assign(out.voxel_count(), 0.0f);
  const Eigen::Matrix3d to_index = A.topLeftCorner<3, 3>().inverse();
  for (int k = 0; k < out.dims[2]; ++k)
    for (int j = 0; j < out.dims[1]; ++j)
      for (int i = 0; i < out.dims[0]; ++i) {
        const Eigen::Vector3d y = (fine_to_lattice * Eigen::Vector4d(i, j, k, 1)).head<3>();  // lattice index
        Eigen::Vector3d x = y;
        for (int it = 0; it < 30; ++it) {  // x + u(x) = y; u varies slowly (strain ≪ 1): converges
          const Eigen::Vector3d next = y - to_index * sample(lat, u, x);
          const bool done = (next - x).squaredNorm() < 1e-8;
          x = next;
          if (done) break;
        }
        const int a = int(std::lround(x[0])), b = int(std::lround(x[1])), c = int(std::lround(x[2]));
        if (a < 0 || b < 0 || c < 0 || a >= lat.dims[0] || b >= lat.dims[1] || c >= lat.dims[2]) continue;
        const std::int32_t e =
            lat.element_of_voxel[std::size_t(a) + std::size_t(lat.dims[0]) * (std::size_t(b) + std::size_t(lat.dims[1]) * c)];
        if (e >= 0) out.values[out.linear_index(i, j, k)] = float(value_of_tissue[lat.tissue_of_element[std::size_t(e)]]);
      }
  return out;
}

}  // namespace vb
