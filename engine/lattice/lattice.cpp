#include "engine/lattice/lattice.hpp"

#include <algorithm>

#include "engine/error.hpp"

namespace vb {

const std::array<std::array<int, 3>, 26>& neighbour_offsets() {
  static const std::array<std::array<int, 3>, 26> offsets = [] {
    std::array<std::array<int, 3>, 26> out{};
    int n = 0;
    for (int order = 1; order <= 3; ++order)  // |d|² = 1 (face), 2 (edge), 3 (corner)
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
            if (dx * dx + dy * dy + dz * dz == order) out[n++] = {dx, dy, dz};
    return out;
  }();
  return offsets;
}

std::array<int, 3> Lattice::voxel_ijk(std::size_t e) const {
  const std::size_t v = voxel_of_element[e];
  const std::size_t nx = dims[0], ny = dims[1];
  return {int(v % nx), int((v / nx) % ny), int(v / (nx * ny))};
}

Eigen::Vector3d Lattice::rest_position(std::size_t e) const {
  const auto ijk = voxel_ijk(e);
  return origin_m + spacing_m * (rotation * Eigen::Vector3d(ijk[0], ijk[1], ijk[2]));
}

Eigen::Matrix4d Lattice::affine() const {
  Eigen::Matrix4d a = Eigen::Matrix4d::Identity();
  a.topLeftCorner<3, 3>() = spacing_m * rotation;
  a.topRightCorner<3, 1>() = origin_m;
  return a;
}

std::array<std::int32_t, 26> Lattice::neighbours(std::size_t e) const {
  std::array<std::int32_t, 26> out;
  const auto ijk = voxel_ijk(e);
  const auto& offsets = neighbour_offsets();
  for (int d = 0; d < 26; ++d) {
    const int i = ijk[0] + offsets[d][0], j = ijk[1] + offsets[d][1], k = ijk[2] + offsets[d][2];
    const bool inside = i >= 0 && j >= 0 && k >= 0 && i < dims[0] && j < dims[1] && k < dims[2];
    out[d] = inside ? element_of_voxel[std::size_t(i) + std::size_t(dims[0]) * (j + std::size_t(dims[1]) * k)] : -1;
  }
  return out;
}

namespace {

/// Majority-vote downsampling: a block is occupied when at least half its voxels are.
LabelVolume downsample_volume(const LabelVolume& in, int f) {
  LabelVolume out;
  for (int a = 0; a < 3; ++a) out.dims[a] = (in.dims[a] + f - 1) / f;
  out.spacing_m = in.spacing_m * f;
  out.rotation = in.rotation;
  out.origin_m = in.origin_m + in.rotation * Eigen::Vector3d::Constant(0.5 * (f - 1) * in.spacing_m);
  out.tissue_names = in.tissue_names;
  out.labels.assign(std::size_t(out.dims[0]) * out.dims[1] * out.dims[2], 0);
  std::vector<int> votes(in.tissue_names.size() + 1);
  for (int K = 0; K < out.dims[2]; ++K)
    for (int J = 0; J < out.dims[1]; ++J)
      for (int I = 0; I < out.dims[0]; ++I) {
        std::fill(votes.begin(), votes.end(), 0);
        for (int k = K * f; k < std::min(in.dims[2], (K + 1) * f); ++k)
          for (int j = J * f; j < std::min(in.dims[1], (J + 1) * f); ++j)
            for (int i = I * f; i < std::min(in.dims[0], (I + 1) * f); ++i)
              ++votes[in.labels[in.linear_index(i, j, k)]];
        const int occupied = f * f * f - votes[0];
        if (2 * occupied < f * f * f) continue;
        votes[0] = -1;
        const auto best = std::max_element(votes.begin(), votes.end()) - votes.begin();
        out.labels[out.linear_index(I, J, K)] = static_cast<std::uint8_t>(best);
      }
  return out;
}

}  // namespace

Lattice build_lattice(const LabelVolume& input, int downsample) {
  require(downsample >= 1, "downsample must be ≥ 1", "model.downsample");
  require(input.labels.size() == std::size_t(input.dims[0]) * input.dims[1] * input.dims[2],
          "label volume size does not match its dimensions");
  const LabelVolume vol = downsample > 1 ? downsample_volume(input, downsample) : input;

  Lattice lat;
  lat.dims = vol.dims;
  lat.spacing_m = vol.spacing_m;
  lat.origin_m = vol.origin_m;
  lat.rotation = vol.rotation;
  lat.tissue_names = vol.tissue_names;
  lat.element_of_voxel.assign(vol.voxel_count(), -1);
  for (std::size_t v = 0; v < vol.voxel_count(); ++v) {
    if (vol.labels[v] == 0) continue;
    require(lat.voxel_of_element.size() < 0x7fffffffu, "model has more than 2^31 elements");
    lat.element_of_voxel[v] = static_cast<std::int32_t>(lat.voxel_of_element.size());
    lat.voxel_of_element.push_back(static_cast<std::uint32_t>(v));
    lat.tissue_of_element.push_back(static_cast<std::uint8_t>(vol.labels[v] - 1));
  }

  // Each pair is seen from both ends; count it once.
  std::size_t half_pairs = 0;
  for (std::size_t e = 0; e < lat.element_count(); ++e)
    for (const std::int32_t j : lat.neighbours(e)) half_pairs += j >= 0;
  lat.connection_count = half_pairs / 2;
  return lat;
}

}  // namespace vb
