#pragma once
/// Analytic solids: point membership and bounding boxes (m).
#include <utility>

#include "engine/scene/scene.hpp"

namespace vb {

/// true when world point p (m) lies inside (or on) the shape
bool shape_contains(const ShapeSpec& shape, const Vec3& p);

/// axis-aligned bounding box (min, max) of the shape (m)
std::pair<Vec3, Vec3> shape_bounds(const ShapeSpec& shape);

}  // namespace vb
