#pragma once
/// Exact signed distance to a closed triangle mesh (docs/FIT.md, "Observation from a surface
/// mesh"): the nearest point on any triangle, found through a bounding-box tree, and the sign from
/// the angle-weighted pseudo-normal of the nearest feature (Bærentzen & Aanæs 2005: the face
/// normal, the sum of an edge's two face normals, or a vertex's angle-weighted normal). Where that
/// feature is non-manifold (an edge of more than two triangles, or a vertex where two parts touch,
/// as where two voxels of a voxel surface meet along an edge) the pseudo-normal is not defined and
/// the sign comes from the generalised winding number over all triangles instead.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/fit/signed_distance.hpp"
#include "engine/geometry/triangle_mesh.hpp"

namespace vb {

class MeshSignedDistance final : public SurfaceDistance {
 public:
  /// Throws vb::Error naming `what` when the mesh is empty, has a non-finite vertex, or is not
  /// closed and consistently oriented (every edge a→b needs as many b→a). An inward-oriented
  /// mesh (negative enclosed volume) is turned outward.
  MeshSignedDistance(TriangleMesh mesh, const std::string& what);
  /// negative inside, positive outside (m)
  double at(const Eigen::Vector3d& p_m) const override;
  /// the generalised winding number at p: 1 inside, 0 outside a closed mesh
  double winding_number(const Eigen::Vector3d& p_m) const;
  double enclosed_volume_m3() const { return volume_m3_; }
  std::size_t triangles() const { return mesh_.triangles.size(); }

 private:
  struct Node {
    Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
    std::uint32_t first = 0, count = 0;  ///< leaf: triangles order_[first, first + count); inner: count = 0
    std::uint32_t left = 0, right = 0;
  };
  std::uint32_t build(std::uint32_t first, std::uint32_t count);

  TriangleMesh mesh_;
  std::vector<Eigen::Vector3d> face_normal_;                ///< unit, outward
  std::vector<std::array<Eigen::Vector3d, 3>> edge_normal_;  ///< per triangle edge (v_k → v_k+1)
  std::vector<std::array<bool, 3>> edge_manifold_;
  std::vector<Eigen::Vector3d> vertex_normal_;  ///< angle-weighted
  std::vector<bool> vertex_manifold_;
  std::vector<std::uint32_t> order_;
  std::vector<Node> nodes_;
  double volume_m3_ = 0;
};

}  // namespace vb
