#pragma once
/// Anchors hold elements in place: sphere (posable by roll/pitch/yaw about its centre),
/// half-space and box regions. Held elements get a prescribed displacement and never move.
#include <Eigen/Geometry>
#include <vector>

#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"

namespace vb {

/// Rotation for roll (about x), pitch (about y), yaw (about z) in degrees: R = Rz·Ry·Rx.
Eigen::Matrix3d rotation_from_rpy_deg(const Vec3& rpy_deg);

/// true when the anchor's region contains world point p (m); the sphere's pose does not change
/// which elements it holds, only where it moves them.
bool anchor_contains(const AnchorSpec& anchor, const Vec3& p);

struct AnchorPlacement {
  std::vector<std::uint8_t> held;  ///< n_elements, 1 = held by some anchor
  /// n_elements (m): the prescribed displacement of held elements; free elements start turned
  /// rigidly with the last posed sphere anchor (zero when none is posed)
  std::vector<Vec3> displacement_m;
  std::vector<std::size_t> held_per_anchor;  ///< count per anchor, in scene order
};

/// Applies every anchor in order (a later anchor's pose wins where regions overlap).
/// Throws vb::Error naming the anchor when one holds no element.
AnchorPlacement place_anchors(const Lattice& lattice, const std::vector<AnchorSpec>& anchors);

}  // namespace vb
