#include "engine/geometry/shapes.hpp"

namespace vb {
namespace {

bool inside_ellipsoid(const Vec3& p, const Vec3& c, const Vec3& radii) {
  return ((p - c).array() / radii.array()).matrix().squaredNorm() <= 1.0;
}

bool on_kept_side(const Vec3& p, const Vec3& c, const Vec3& axis) { return (p - c).dot(axis) >= 0.0; }

}  // namespace

bool shape_contains(const ShapeSpec& s, const Vec3& p) {
  switch (s.kind) {
    case ShapeSpec::Kind::Box:
      return (p.array() >= s.min_m.array()).all() && (p.array() <= s.max_m.array()).all();
    case ShapeSpec::Kind::Sphere:
      return (p - s.center_m).squaredNorm() <= s.radius_m * s.radius_m;
    case ShapeSpec::Kind::Ellipsoid:
      return inside_ellipsoid(p, s.center_m, s.radii_m);
    case ShapeSpec::Kind::HalfEllipsoid:
      return inside_ellipsoid(p, s.center_m, s.radii_m) && on_kept_side(p, s.center_m, s.axis);
    case ShapeSpec::Kind::Hemisphere:
      return (p - s.center_m).squaredNorm() <= s.radius_m * s.radius_m &&
             on_kept_side(p, s.center_m, s.axis);
  }
  return false;
}

std::pair<Vec3, Vec3> shape_bounds(const ShapeSpec& s) {
  switch (s.kind) {
    case ShapeSpec::Kind::Box:
      return {s.min_m, s.max_m};
    case ShapeSpec::Kind::Sphere:
    case ShapeSpec::Kind::Hemisphere:
      return {s.center_m.array() - s.radius_m, s.center_m.array() + s.radius_m};
    case ShapeSpec::Kind::Ellipsoid:
    case ShapeSpec::Kind::HalfEllipsoid:
      return {s.center_m - s.radii_m, s.center_m + s.radii_m};
  }
  return {Vec3::Zero(), Vec3::Zero()};
}

}  // namespace vb
