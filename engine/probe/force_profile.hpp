#pragma once
/// Reading force–displacement curves and force profiles (docs/PROBING.md): the depth at which a
/// press reaches a force, and the full width at half maximum of a profile's excess.
#include <vector>

namespace vb {

/// Depth (m) at which the force first reaches `force_n`, linear between samples (force_n[0] at
/// depth_m[0]); NaN when the curve never reaches it.
double depth_at_force(const std::vector<double>& depth_m, const std::vector<double>& force_n, double force_n_target);

/// Full width at half maximum of y(s) (same units as s): the distance between the two points,
/// interpolated linearly, where y crosses half its maximum on either side of the maximum; the
/// line's ends when it never falls that low (so the width is then a lower bound). 0 when max ≤ 0.
double full_width_half_maximum(const std::vector<double>& s, const std::vector<double>& y);

}  // namespace vb
