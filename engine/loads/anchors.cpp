#include "engine/loads/anchors.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "engine/error.hpp"

namespace vb {

Eigen::Matrix3d rotation_from_rpy_deg(const Vec3& rpy_deg) {
  const Vec3 r = rpy_deg * (std::numbers::pi / 180.0);
  return (Eigen::AngleAxisd(r.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(r.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(r.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

bool anchor_contains(const AnchorSpec& a, const Vec3& p) {
  switch (a.kind) {
    case AnchorSpec::Kind::Sphere:
      return (p - a.center_m).squaredNorm() <= a.radius_m * a.radius_m;
    case AnchorSpec::Kind::HalfSpace:
      return (p - a.point_m).dot(a.normal) >= 0.0;
    case AnchorSpec::Kind::Box:
      return (p.array() >= a.min_m.array()).all() && (p.array() <= a.max_m.array()).all();
  }
  return false;
}

AnchorPlacement place_anchors(const Lattice& lattice, const std::vector<AnchorSpec>& anchors) {
  const std::size_t n = lattice.element_count();
  AnchorPlacement out;
  out.held.assign(n, 0);
  out.displacement_m.assign(n, Vec3::Zero());
  for (const AnchorSpec& a : anchors) {
    const bool posed = a.kind == AnchorSpec::Kind::Sphere && a.rpy_deg.squaredNorm() > 0;
    const Eigen::Matrix3d R = posed ? rotation_from_rpy_deg(a.rpy_deg) : Eigen::Matrix3d::Identity();
    std::size_t count = 0;
    for (std::size_t e = 0; e < n; ++e) {
      const Vec3 X = lattice.rest_position(e);
      if (!anchor_contains(a, X)) continue;
      out.held[e] = 1;
      out.displacement_m[e] = posed ? Vec3(R * (X - a.center_m) + a.center_m - X) : Vec3::Zero();
      ++count;
    }
    require(count > 0, "anchor '" + a.name + "' holds no element",
            "anchor." + a.name + (a.line ? " (line " + std::to_string(a.line) + ")" : ""),
            "move or enlarge it so it overlaps the model");
    out.held_per_anchor.push_back(count);
  }
  // A posed sphere turns the patient as a whole: free elements start turned with the last one, so
  // a posture change does not begin with the chest wall torn from the tissue in front of it.
  const auto posed_sphere = [](const AnchorSpec& a) { return a.kind == AnchorSpec::Kind::Sphere && a.rpy_deg.squaredNorm() > 0; };
  const auto last = std::find_if(anchors.rbegin(), anchors.rend(), posed_sphere);
  if (last != anchors.rend()) {
    const Eigen::Matrix3d R = rotation_from_rpy_deg(last->rpy_deg);
    for (std::size_t e = 0; e < n; ++e) {
      if (out.held[e]) continue;
      const Vec3 X = lattice.rest_position(e);
      out.displacement_m[e] = R * (X - last->center_m) + last->center_m - X;
    }
  }
  return out;
}

}  // namespace vb
