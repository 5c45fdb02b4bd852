#include "engine/surface/surface_area.hpp"

#include <Eigen/Geometry>

namespace vb {

std::vector<double> element_surface_area_m2(const SurfaceMesh& mesh, std::span<const double> x) {
  std::vector<double> area(x.size() / 3, 0.0);
  const auto at = [&](std::uint32_t v) {
    const std::size_t e = mesh.element_of_vertex[v];
    return Eigen::Vector3d(x[3 * e], x[3 * e + 1], x[3 * e + 2]);
  };
  for (const auto& t : mesh.triangles) {
    const double third = (at(t[1]) - at(t[0])).cross(at(t[2]) - at(t[0])).norm() / 6;
    for (const std::uint32_t v : t) area[mesh.element_of_vertex[v]] += third;
  }
  return area;
}

}  // namespace vb
