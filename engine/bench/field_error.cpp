#include "engine/bench/field_error.hpp"

#include <algorithm>
#include <cmath>

#include "engine/error.hpp"

namespace vb::bench {
namespace {

using Eigen::Vector3d;

/// Displacement of the element nearest to lattice coordinate q (in voxels), searching shells of
/// growing radius around the nearest voxel; the lattice has at least one element.
Vector3d nearest_element_displacement(const Lattice& lat, const std::vector<double>& u, const Vector3d& q) {
  const int c[3] = {int(std::lround(q.x())), int(std::lround(q.y())), int(std::lround(q.z()))};
  const int reach = std::max({lat.dims[0], lat.dims[1], lat.dims[2]});
  for (int r = 0; r <= reach; ++r) {
    double best = INFINITY;
    std::int64_t found = -1;
    for (int k = c[2] - r; k <= c[2] + r; ++k)
      for (int j = c[1] - r; j <= c[1] + r; ++j)
        for (int i = c[0] - r; i <= c[0] + r; ++i) {
          if (std::max({std::abs(i - c[0]), std::abs(j - c[1]), std::abs(k - c[2])}) != r) continue;  // shell only
          if (i < 0 || j < 0 || k < 0 || i >= lat.dims[0] || j >= lat.dims[1] || k >= lat.dims[2]) continue;
          const std::int32_t e = lat.element_of_voxel[std::size_t(i) + std::size_t(lat.dims[0]) * (j + std::size_t(lat.dims[1]) * k)];
          if (e < 0) continue;
          const double d2 = (Vector3d(i, j, k) - q).squaredNorm();
          if (d2 < best) best = d2, found = e;
        }
    if (found >= 0) return Vector3d(u[3 * found], u[3 * found + 1], u[3 * found + 2]);
  }
  throw Error("cannot sample a displacement field of an empty lattice", "bench");
}

}  // namespace

std::vector<Vector3d> sample_displacement(const Lattice& lat, const std::vector<double>& u,
                                          const std::vector<Vector3d>& points) {
  require(u.size() == 3 * lat.element_count(), "displacement field does not match its lattice", "bench");
  std::vector<Vector3d> out(points.size());
  for (std::size_t p = 0; p < points.size(); ++p) {
    Vector3d q = lat.rotation.transpose() * (points[p] - lat.origin_m) / lat.spacing_m;
    int base[3];
    double frac[3];
    for (int a = 0; a < 3; ++a) {
      q[a] = std::clamp(q[a], 0.0, double(lat.dims[a] - 1));
      if (std::abs(q[a] - std::round(q[a])) < 1e-9) q[a] = std::round(q[a]);  // on a centre: that centre alone
      base[a] = std::min(int(std::floor(q[a])), std::max(lat.dims[a] - 2, 0));
      frac[a] = q[a] - base[a];
    }
    Vector3d sum = Vector3d::Zero();
    double weight = 0;
    for (int corner = 0; corner < 8; ++corner) {
      int ijk[3];
      double w = 1;
      for (int a = 0; a < 3; ++a) {
        const int up = (corner >> a) & 1;
        ijk[a] = base[a] + up;
        w *= up ? frac[a] : 1 - frac[a];
      }
      if (w == 0 || ijk[0] >= lat.dims[0] || ijk[1] >= lat.dims[1] || ijk[2] >= lat.dims[2]) continue;
      const std::int32_t e =
          lat.element_of_voxel[std::size_t(ijk[0]) + std::size_t(lat.dims[0]) * (ijk[1] + std::size_t(lat.dims[1]) * ijk[2])];
      if (e < 0) continue;
      sum += w * Vector3d(u[3 * e], u[3 * e + 1], u[3 * e + 2]);
      weight += w;
    }
    out[p] = weight > 0 ? Vector3d(sum / weight) : nearest_element_displacement(lat, u, q);
  }
  return out;
}

FieldError field_error(const std::vector<Vector3d>& u, const std::vector<Vector3d>& u_ref) {
  require(u.size() == u_ref.size() && !u.empty(), "fields to compare differ in size or are empty", "bench");
  FieldError e;
  double sum_sq = 0;
  for (std::size_t p = 0; p < u.size(); ++p) {
    const double d = (u[p] - u_ref[p]).norm();
    e.max_m = std::max(e.max_m, d);
    sum_sq += d * d;
  }
  e.rms_m = std::sqrt(sum_sq / double(u.size()));
  return e;
}

double top_layer_mean_uz(const Lattice& lat, const std::vector<double>& u) {
  int top = -1;
  for (std::size_t e = 0; e < lat.element_count(); ++e) top = std::max(top, lat.voxel_ijk(e)[2]);
  double sum = 0;
  int count = 0;
  for (std::size_t e = 0; e < lat.element_count(); ++e)
    if (lat.voxel_ijk(e)[2] == top) sum += u[3 * e + 2], ++count;
  return count ? sum / count : 0.0;
}

}  // namespace vb::bench
