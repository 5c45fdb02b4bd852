#include "engine/fit/deformed_surface.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <unordered_map>

#include "engine/error.hpp"
#include "engine/fit/interpolated_displacement.hpp"

namespace vb {

TriangleMesh deformed_boundary_mesh(const Lattice& lat, const std::vector<double>& change_m, int tissue) {
  const auto in_region = [&](int i, int j, int k) {
    if (i < 0 || j < 0 || k < 0 || i >= lat.dims[0] || j >= lat.dims[1] || k >= lat.dims[2]) return false;
    const std::int32_t e = lat.element_of_voxel[std::size_t(i) + std::size_t(lat.dims[0]) * (std::size_t(j) + std::size_t(lat.dims[1]) * k)];
    return e >= 0 && (tissue < 0 || lat.tissue_of_element[std::size_t(e)] == tissue);
  };
  double largest = 0;
  for (std::size_t e = 0; e < lat.element_count(); ++e)
    largest = std::max(largest, std::hypot(change_m[3 * e], change_m[3 * e + 1], change_m[3 * e + 2]));
  const InterpolatedDisplacement u(lat, change_m, int(std::ceil(largest / lat.spacing_m)) + 2);
  const Eigen::Matrix4d A = lat.affine();
  // a mirroring voxel → world map turns the winding: keep (x1 − x0) × (x2 − x0) outward in the world
  const bool mirrored = A.topLeftCorner<3, 3>().determinant() < 0;

  TriangleMesh mesh;
  std::unordered_map<std::size_t, std::uint32_t> vertex_of_corner;
  const std::size_t cx = std::size_t(lat.dims[0]) + 1, cy = std::size_t(lat.dims[1]) + 1;
  const auto vertex = [&](const std::array<int, 3>& c) {  // voxel corner c: lattice index c − ½
    const std::size_t key = std::size_t(c[0]) + cx * (std::size_t(c[1]) + cy * std::size_t(c[2]));
    const auto [it, added] = vertex_of_corner.try_emplace(key, std::uint32_t(mesh.vertices_m.size()));
    if (added) {
      const Eigen::Vector3d index(c[0] - 0.5, c[1] - 0.5, c[2] - 0.5);
      mesh.vertices_m.push_back((A * index.homogeneous()).head<3>() + u.at_index(index));
    }
    return it->second;
  };
  for (std::size_t e = 0; e < lat.element_count(); ++e) {
    const auto ijk = lat.voxel_ijk(e);
    if (!in_region(ijk[0], ijk[1], ijk[2])) continue;
    for (int a = 0; a < 3; ++a)
      for (const int side : {-1, 1}) {
        std::array<int, 3> n = ijk;
        n[std::size_t(a)] += side;
        if (in_region(n[0], n[1], n[2])) continue;
        // the face's corners, counter-clockwise seen from the + side of axis a (b = a+1, c = a+2)
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        std::array<std::uint32_t, 4> q;
        const int steps[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        for (int s = 0; s < 4; ++s) {
          std::array<int, 3> corner = ijk;
          corner[std::size_t(a)] += side > 0 ? 1 : 0;
          corner[std::size_t(b)] += steps[s][0];
          corner[std::size_t(c)] += steps[s][1];
          q[std::size_t(s)] = vertex(corner);
        }
        if ((side < 0) != mirrored) std::swap(q[1], q[3]);  // seen from the − side
        mesh.triangles.push_back({q[0], q[1], q[2]});
        mesh.triangles.push_back({q[0], q[2], q[3]});
      }
  }
  require(!mesh.triangles.empty(), "the region has no element", "deformed_boundary_mesh");
  return mesh;
}

}  // namespace vb
