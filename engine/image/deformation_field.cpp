#include "engine/image/deformation_field.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <tuple>

#include "engine/error.hpp"
#include "engine/image/parallel_items.hpp"

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

void for_each_slice(const ImageVolume& grid, const std::function<void(int k)>& slice, const ImageProgress& progress) {
  const std::size_t slices = std::size_t(std::max(0, grid.dims[2]));
  for_each_index_dynamic(slices, [&](std::size_t k) { slice(int(k)); }, [&](std::size_t done) {
    if (progress) progress(double(done) / double(slices));
  });
}

namespace {

/// Calls f(i, j, k, world centre) for every voxel of the grid, slices on all cores.
template <class F>
void for_each_voxel(const ImageVolume& grid, F&& f, const ImageProgress& progress = {}) {
  for_each_slice(grid, [&](int k) {
    for (int j = 0; j < grid.dims[1]; ++j)
      for (int i = 0; i < grid.dims[0]; ++i) f(i, j, k, grid.world_of_index(Eigen::Vector3d(i, j, k)));
  }, progress);
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

std::vector<float> forward_displacement_on_grid(const LatticeField& field, const ImageVolume& grid,
                                                const ImageProgress& progress) {
  std::vector<float> out(3 * grid.voxel_count(), 0.f);
  for_each_voxel(grid, [&](int i, int j, int k, const Eigen::Vector3d& p) {
    const Eigen::Vector3d u = field.displacement_at(p);
    const std::size_t v = grid.linear_index(i, j, k);
    for (int c = 0; c < 3; ++c) out[3 * v + c] = float(u[c]);
  }, progress);
  return out;
}

namespace {

/// Where tissue ends up: the elements by the CT voxel their displaced centre lies in (the
/// starting guesses for inverting x + u(x) = y near moved tissue), kept per block of `block`³
/// voxels (a few bytes per element, nothing per voxel).
class Seeds {
 public:
  Seeds(const ImageVolume& ct, const Lattice& lattice, const std::vector<double>& u, int reach)
      : ct_(ct), reach_(reach), block_(std::max(1, reach)) {
    for (int a = 0; a < 3; ++a) blocks_[a] = (ct.dims[a] + block_ - 1) / block_;
    const Eigen::Matrix4d to_index = ct.affine_lps_m.inverse();
    // The voxel element e landed in, if inside the CT.
    const auto landed = [&](std::size_t e, std::array<int, 3>& v) {
      const Eigen::Vector3d y = lattice.rest_position(e) + Eigen::Vector3d(u[3 * e], u[3 * e + 1], u[3 * e + 2]);
      const Eigen::Vector3d q = (to_index * y.homogeneous()).head<3>();
      for (int a = 0; a < 3; ++a) v[std::size_t(a)] = int(std::lround(q[a]));
      return v[0] >= 0 && v[1] >= 0 && v[2] >= 0 && v[0] < ct.dims[0] && v[1] < ct.dims[1] && v[2] < ct.dims[2];
    };
    // A counting sort by block in two passes (count, then place): entries in element order within
    // each block, and nothing held per element beyond the entries themselves.
    start_.assign(std::size_t(blocks_[0]) * blocks_[1] * blocks_[2] + 1, 0);
    std::array<int, 3> v{};
    for (std::size_t e = 0; e < lattice.element_count(); ++e)
      if (landed(e, v)) ++start_[block_of(v[0] / block_, v[1] / block_, v[2] / block_) + 1];
    for (std::size_t b = 1; b < start_.size(); ++b) start_[b] += start_[b - 1];
    entries_.resize(start_.back());
    std::vector<std::size_t> next(start_.begin(), start_.end() - 1);
    for (std::size_t e = 0; e < lattice.element_count(); ++e)
      if (landed(e, v)) entries_[next[block_of(v[0] / block_, v[1] / block_, v[2] / block_)]++] = Entry{v, std::int64_t(e)};
  }

  /// The elements that landed within `reach` voxels of (i, j, k) along each axis, nearest (in
  /// metres) first, ties in element order; `out` is reused.
  void near(int i, int j, int k, std::vector<std::pair<double, std::int64_t>>& out) const {
    out.clear();
    const Eigen::Matrix3d axes = ct_.affine_lps_m.topLeftCorner<3, 3>();
    const int at[3] = {i, j, k};
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(0, at[a] - reach_) / block_;
      hi[a] = std::min(ct_.dims[a] - 1, at[a] + reach_) / block_;
    }
    for (int c = lo[2]; c <= hi[2]; ++c)
      for (int b = lo[1]; b <= hi[1]; ++b)
        for (int a = lo[0]; a <= hi[0]; ++a) {
          const std::size_t block = block_of(a, b, c);
          for (std::size_t n = start_[block]; n < start_[block + 1]; ++n) {
            const Entry& s = entries_[n];
            const Eigen::Vector3i d(s.voxel[0] - i, s.voxel[1] - j, s.voxel[2] - k);
            if (d.cwiseAbs().maxCoeff() > reach_) continue;
            out.emplace_back((axes * d.cast<double>()).squaredNorm(), s.element);
          }
        }
    std::sort(out.begin(), out.end());
  }

 private:
  struct Entry {
    std::array<int, 3> voxel;
    std::int64_t element;
  };
  std::size_t block_of(int a, int b, int c) const {
    return std::size_t(a) + std::size_t(blocks_[0]) * (std::size_t(b) + std::size_t(blocks_[1]) * std::size_t(c));
  }
  const ImageVolume& ct_;
  int reach_, block_;
  std::array<int, 3> blocks_{0, 0, 0};
  std::vector<std::size_t> start_;  ///< per block, its first entry; one past the end last
  std::vector<Entry> entries_;
};

/// Solves x + u(x) = y for a tissue point x (inside the model) by fixed-point iteration from a
/// start: iterations stop once |x + u(x) − y| is below a millionth of the smallest CT spacing,
/// and a solution counts within a thousandth of it.
class TissueSource {
 public:
  TissueSource(const LatticeField& field, const ImageVolume& ct, int iterations)
      : field_(field), iterations_(iterations), tolerance_(1e-3 * ct.spacing_m().minCoeff()) {}
  /// true with `found` and its `residual` when the iteration from `x` meets the tolerance in the model.
  bool operator()(const Eigen::Vector3d& y, Eigen::Vector3d x, Eigen::Vector3d& found, double& residual) const {
    const double converged = 1e-3 * tolerance_;  // iterations stop here; acceptance is at tolerance_
    for (int it = 0;; ++it) {
      const Eigen::Vector3d miss = x + field_.displacement_at(x) - y;
      residual = miss.norm();
      if (residual <= converged || it == iterations_) break;
      x -= miss;
    }
    if (!(residual <= tolerance_) || field_.element_at(x) < 0) return false;
    found = x;
    return true;
  }

 private:
  const LatticeField& field_;
  int iterations_;
  double tolerance_;
};

}  // namespace

WarpResult warp_image(const ImageVolume& ct, const Lattice& lattice, const std::vector<double>& u, int iterations,
                      const ImageProgress& progress) {
  const LatticeField field(lattice, u);
  WarpResult r;
  r.warped = ct;
  r.inverse_field.assign(3 * ct.voxel_count(), 0.f);
  const Eigen::Matrix4d to_index = ct.affine_lps_m.inverse();
  const float background = *std::min_element(ct.values.begin(), ct.values.end());
  // Search radius for seeds: lattice elements can be sparser than CT voxels.
  const int reach = 1 + int(std::ceil(lattice.spacing_m / ct.spacing_m().minCoeff()));
  const Seeds seeds(ct, lattice, u, reach);
  const TissueSource tissue_source(field, ct, iterations);
  std::vector<double> slice_residual(std::size_t(std::max(0, ct.dims[2])), 0.0);
  std::vector<std::size_t> slice_vacated(slice_residual.size(), 0);
  for_each_slice(ct, [&](int k) {
    std::vector<std::pair<double, std::int64_t>> candidates;
    for (int j = 0; j < ct.dims[1]; ++j) {
      bool previous_found = false;
      Eigen::Vector3d previous_offset = Eigen::Vector3d::Zero();
      for (int i = 0; i < ct.dims[0]; ++i) {
        const Eigen::Vector3d y = ct.world_of_index(Eigen::Vector3d(i, j, k));
        const std::size_t v = ct.linear_index(i, j, k);
        Eigen::Vector3d x;
        double residual = 0;
        bool found = previous_found && tissue_source(y, y + previous_offset, x, residual);
        if (!found) found = tissue_source(y, y, x, residual);
        if (!found) {
          seeds.near(i, j, k, candidates);
          for (const auto& [distance, e] : candidates) {
            found = tissue_source(y, y - Eigen::Vector3d(u[3 * e], u[3 * e + 1], u[3 * e + 2]), x, residual);
            if (found) break;
          }
        }
        previous_found = found;
        if (found) {
          previous_offset = x - y;
          slice_residual[std::size_t(k)] = std::max(slice_residual[std::size_t(k)], residual);
          const Eigen::Vector3d q = (to_index * x.homogeneous()).head<3>();
          r.warped.values[v] = sample(ct, q);
          for (int c = 0; c < 3; ++c) r.inverse_field[3 * v + c] = float(x[c] - y[c]);
        } else if (field.element_at(y) >= 0) {  // tissue left this voxel and none arrived
          r.warped.values[v] = background;
          ++slice_vacated[std::size_t(k)];
        }  // else: background that no tissue reaches keeps its value
      }
    }
  }, progress);
  for (std::size_t k = 0; k < slice_residual.size(); ++k) {
    r.max_fixed_point_residual_m = std::max(r.max_fixed_point_residual_m, slice_residual[k]);
    r.vacated_voxels += slice_vacated[k];
  }
  return r;
}

ImageVolume warp_labels(const ImageVolume& labels, const Lattice& lattice, const std::vector<double>& u,
                        const std::vector<float>& inverse_field, int iterations, const ImageProgress& progress) {
  require(inverse_field.size() == 3 * labels.voxel_count(), "the inverse field's grid is not the label map's");
  const LatticeField field(lattice, u);
  const TissueSource tissue_source(field, labels, iterations);
  const Eigen::Matrix4d to_index = labels.affine_lps_m.inverse();
  ImageVolume out = labels;
  for_each_voxel(labels, [&](int i, int j, int k, const Eigen::Vector3d& y) {
    const std::size_t v = labels.linear_index(i, j, k);
    const Eigen::Vector3d d(inverse_field[3 * v], inverse_field[3 * v + 1], inverse_field[3 * v + 2]);
    Eigen::Vector3d x = y + d;
    if (d.isZero()) {  // solved where it stands, vacated, or never reached: warp_image's own test
      if (field.element_at(y) < 0) return;  // outside the model: no tissue arrived, keeps its label
      double residual = 0;
      if (!tissue_source(y, y, x, residual)) {
        out.values[v] = 0;  // tissue left and none arrived
        return;
      }
    }
    const Eigen::Vector3d q = (to_index * x.homogeneous()).head<3>();
    const int a = std::clamp(int(std::lround(q[0])), 0, labels.dims[0] - 1),
              b = std::clamp(int(std::lround(q[1])), 0, labels.dims[1] - 1),
              c = std::clamp(int(std::lround(q[2])), 0, labels.dims[2] - 1);
    out.values[v] = labels.values[labels.linear_index(a, b, c)];
  }, progress);
  return out;
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
