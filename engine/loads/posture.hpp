#pragma once
/// Gravity direction for a named patient posture, in the body frame.
///
/// Body frame = DICOM LPS patient coordinates: x → patient Left, y → Posterior, z → Superior.
/// The posture names the patient's position in the world; gravity is expressed in the body frame
/// because the model is built from an image in patient coordinates.
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"

namespace vb {

/// Standard gravity (m/s²).
inline constexpr double kStandardGravity_m_s2 = 9.80665;

/// Names gravity_for_posture accepts, in documentation order.
const std::vector<std::string>& posture_names();

/// Gravitational acceleration (m/s², magnitude kStandardGravity_m_s2) in the LPS body frame:
/// supine (0, +g, 0), prone (0, -g, 0), upright (0, 0, -g), left_lateral (+g, 0, 0),
/// right_lateral (-g, 0, 0). Throws vb::Error listing the names for an unknown one.
Vec3 gravity_for_posture(const std::string& name);

}  // namespace vb
