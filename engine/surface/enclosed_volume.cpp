#include "engine/surface/enclosed_volume.hpp"

#include <Eigen/Geometry>

#include "engine/error.hpp"

namespace vb {
namespace {

void check_sizes(const SurfaceMesh& mesh, std::span<const double> positions_m) {
  require(positions_m.size() % 3 == 0, "positions must be n_elements × 3");
  for (const std::uint32_t e : mesh.element_of_vertex)
    require(3 * std::size_t(e) + 2 < positions_m.size(), "positions do not cover the mesh's elements");
}

Eigen::Vector3d position(std::span<const double> x, std::uint32_t e) {
  return {x[3 * std::size_t(e)], x[3 * std::size_t(e) + 1], x[3 * std::size_t(e) + 2]};
}

Eigen::Vector3d reference_point(const SurfaceMesh& mesh, std::span<const double> x) {
  return mesh.element_of_vertex.empty() ? Eigen::Vector3d::Zero() : position(x, mesh.element_of_vertex[0]);
}

}  // namespace

double enclosed_volume_m3(const SurfaceMesh& mesh, std::span<const double> positions_m) {
  check_sizes(mesh, positions_m);
  const Eigen::Vector3d o = reference_point(mesh, positions_m);
  double six_v = 0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = position(positions_m, mesh.element_of_vertex[t[0]]) - o;
    const Eigen::Vector3d b = position(positions_m, mesh.element_of_vertex[t[1]]) - o;
    const Eigen::Vector3d c = position(positions_m, mesh.element_of_vertex[t[2]]) - o;
    six_v += a.dot(b.cross(c));
  }
  return six_v / 6.0;
}

std::vector<double> volume_gradient_m2(const SurfaceMesh& mesh, std::span<const double> positions_m) {
  check_sizes(mesh, positions_m);
  std::vector<double> g(positions_m.size(), 0.0);
  const Eigen::Vector3d o = reference_point(mesh, positions_m);
  for (const auto& t : mesh.triangles) {
    const std::uint32_t e[3] = {mesh.element_of_vertex[t[0]], mesh.element_of_vertex[t[1]],
                                mesh.element_of_vertex[t[2]]};
    const Eigen::Vector3d x[3] = {position(positions_m, e[0]) - o, position(positions_m, e[1]) - o,
                                  position(positions_m, e[2]) - o};
    // ∂(a·(b×c))/∂a = b×c, and cyclically.
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d d = x[(k + 1) % 3].cross(x[(k + 2) % 3]) / 6.0;
      for (int c = 0; c < 3; ++c) g[3 * std::size_t(e[k]) + c] += d[c];
    }
  }
  return g;
}

}  // namespace vb
