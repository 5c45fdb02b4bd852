#include "engine/fit/observation.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "engine/error.hpp"

namespace vb {
namespace {

/// Nearest voxel of `image` to world point p, or −1 outside.
std::int64_t nearest_voxel(const ImageVolume& image, const Eigen::Matrix4d& to_index, const Eigen::Vector3d& p) {
  const Eigen::Vector3d q = (to_index * p.homogeneous()).head<3>();
  const int i = int(std::lround(q.x())), j = int(std::lround(q.y())), k = int(std::lround(q.z()));
  if (i < 0 || j < 0 || k < 0 || i >= image.dims[0] || j >= image.dims[1] || k >= image.dims[2]) return -1;
  return std::int64_t(image.linear_index(i, j, k));
}

}  // namespace

std::size_t Observation::observed_elements() const {
  return std::size_t(std::count_if(weight_per_m2.begin(), weight_per_m2.end(), [](double w) { return w > 0; }));
}

Observation observation_from_field(const Lattice& lattice, const ImageVolume& grid,
                                   const std::vector<float>& field, double sigma_m) {
  require(field.size() == 3 * grid.voxel_count(), "the displacement field does not match its grid", "fit.dvf");
  const std::size_t n = lattice.element_count();
  Observation obs;
  obs.displacement_m.assign(3 * n, 0.0);
  obs.weight_per_m2.assign(n, 0.0);
  const Eigen::Matrix4d to_index = grid.affine_lps_m.inverse();
  const double eps = 1e-6;
  for (std::size_t e = 0; e < n; ++e) {
    const Eigen::Vector3d q = (to_index * lattice.rest_position(e).homogeneous()).head<3>();
    bool inside = true;
    for (int a = 0; a < 3; ++a) inside = inside && q[a] > -eps && q[a] < grid.dims[a] - 1 + eps;
    if (!inside) continue;
    int base[3];
    double frac[3];
    for (int a = 0; a < 3; ++a) {
      base[a] = std::clamp(int(std::floor(q[a])), 0, std::max(0, grid.dims[a] - 2));
      frac[a] = std::clamp(q[a] - base[a], 0.0, 1.0);
    }
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    for (int c = 0; c < 8; ++c) {
      const int o[3] = {c & 1, (c >> 1) & 1, (c >> 2) & 1};
      double w = 1;
      int ijk[3];
      for (int a = 0; a < 3; ++a) {
        ijk[a] = std::min(base[a] + o[a], grid.dims[a] - 1);
        w *= o[a] ? frac[a] : 1 - frac[a];
      }
      if (w == 0) continue;
      const std::size_t v = grid.linear_index(ijk[0], ijk[1], ijk[2]);
      d += w * Eigen::Vector3d(field[3 * v], field[3 * v + 1], field[3 * v + 2]);
    }
    for (int a = 0; a < 3; ++a) obs.displacement_m[3 * e + a] = d[a];
    obs.weight_per_m2[e] = 1 / (sigma_m * sigma_m);
  }
  require(obs.observed_elements() > 0, "the displacement field covers no element of the model", "fit.dvf",
          "check that the field is on the model image's grid (LPS frame)");
  return obs;
}

void apply_mask(Observation& obs, const Lattice& lattice, const ImageVolume& mask) {
  const Eigen::Matrix4d to_index = mask.affine_lps_m.inverse();
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    const std::int64_t v = nearest_voxel(mask, to_index, lattice.rest_position(e));
    if (v < 0 || mask.values[std::size_t(v)] == 0) obs.weight_per_m2[e] = 0;
  }
}

void apply_sigma_image(Observation& obs, const Lattice& lattice, const ImageVolume& sigma_mm) {
  const Eigen::Matrix4d to_index = sigma_mm.affine_lps_m.inverse();
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    if (obs.weight_per_m2[e] == 0) continue;
    const std::int64_t v = nearest_voxel(sigma_mm, to_index, lattice.rest_position(e));
    const double s = v < 0 ? 0.0 : sigma_mm.values[std::size_t(v)] * 1e-3;
    obs.weight_per_m2[e] = s > 0 ? 1 / (s * s) : 0.0;
  }
}

Observation observation_from_landmarks(const Lattice& lattice, const std::vector<Landmark>& landmarks, double sigma_m) {
  const std::size_t n = lattice.element_count();
  Observation obs;
  obs.displacement_m.assign(3 * n, 0.0);
  obs.weight_per_m2.assign(n, 0.0);
  const Eigen::Matrix4d to_lattice = lattice.affine().inverse();
  for (std::size_t i = 0; i < landmarks.size(); ++i) {
    const Landmark& l = landmarks[i];
    const Eigen::Vector3d q = (to_lattice * l.point_m.homogeneous()).head<3>();
    const int a = int(std::lround(q.x())), b = int(std::lround(q.y())), c = int(std::lround(q.z()));
    std::int32_t e = -1;
    if (a >= 0 && b >= 0 && c >= 0 && a < lattice.dims[0] && b < lattice.dims[1] && c < lattice.dims[2])
      e = lattice.element_of_voxel[std::size_t(a) + std::size_t(lattice.dims[0]) * (std::size_t(b) + std::size_t(lattice.dims[1]) * c)];
    const std::string where = "fit.landmarks row " + std::to_string(i + 1);
    require(e >= 0, "landmark outside the model", where, "landmarks are points of the model's image (LPS mm)");
    require(obs.weight_per_m2[std::size_t(e)] == 0, "two landmarks fall in one element", where,
            "merge them or refine the lattice");
    const double s = l.sigma_m > 0 ? l.sigma_m : sigma_m;
    obs.weight_per_m2[std::size_t(e)] = 1 / (s * s);
    for (int k = 0; k < 3; ++k) obs.displacement_m[3 * std::size_t(e) + k] = l.displacement_m[k];
  }
  return obs;
}

ResidualStats residual_stats(const Observation& obs, const std::vector<double>& sim) {
  std::vector<double> d;
  for (std::size_t e = 0; e < obs.weight_per_m2.size(); ++e) {
    if (obs.weight_per_m2[e] <= 0) continue;
    d.push_back(std::hypot(sim[3 * e] - obs.displacement_m[3 * e], sim[3 * e + 1] - obs.displacement_m[3 * e + 1],
                           sim[3 * e + 2] - obs.displacement_m[3 * e + 2]));
  }
  return distance_stats(std::move(d));
}

ResidualStats distance_stats(std::vector<double> d) {
  ResidualStats s;
  s.elements = d.size();
  if (d.empty()) return s;
  double sq = 0;
  std::size_t within = 0;
  for (double x : d) {
    sq += x * x;
    s.mean_m += x;
    within += x <= 1e-3;
  }
  s.rms_m = std::sqrt(sq / double(d.size()));
  s.mean_m /= double(d.size());
  s.within_1mm = double(within) / double(d.size());
  std::sort(d.begin(), d.end());
  s.max_m = d.back();
  s.p95_m = d[std::min(d.size() - 1, std::size_t(std::ceil(0.95 * double(d.size()))) - 1)];
  return s;
}

}  // namespace vb
