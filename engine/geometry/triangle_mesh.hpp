#pragma once
/// A plain triangle mesh in the world frame (device parts for viewers; the breast surface, whose
/// vertices are elements, is engine/surface/surface_mesh.hpp).
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace vb {

struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices_m;  ///< world frame (m)
  /// vertex ids, counter-clockwise seen from outside: (x1 − x0) × (x2 − x0) points out
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

}  // namespace vb
