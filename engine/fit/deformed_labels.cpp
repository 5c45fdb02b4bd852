#include "engine/fit/deformed_labels.hpp"

#include "engine/fit/interpolated_displacement.hpp"

#include <Eigen/LU>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace vb {

ImageVolume deformed_label_map(const Lattice& lat, const std::vector<double>& change_m,
                               const std::vector<int>& value_of_tissue, int subdivide) {
  double largest = 0;
  for (std::size_t e = 0; e < lat.element_count(); ++e)
    largest = std::max(largest, std::hypot(change_m[3 * e], change_m[3 * e + 1], change_m[3 * e + 2]));
  const int s = std::max(1, subdivide);
  const int margin = int(std::ceil(largest / lat.spacing_m * s)) + 2;  // fine voxels past the lattice
  const int passes = int(std::ceil(largest / lat.spacing_m)) + 2;
  const InterpolatedDisplacement u(lat, change_m, passes);

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
          const Eigen::Vector3d next = y - to_index * u.at_index(x);
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
