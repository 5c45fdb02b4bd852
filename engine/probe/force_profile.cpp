#include "engine/probe/force_profile.hpp"

#include <algorithm>
#include <cmath>

namespace vb {

double depth_at_force(const std::vector<double>& depth, const std::vector<double>& force, double target) {
  for (std::size_t k = 0; k < force.size(); ++k) {
    if (force[k] < target) continue;
    if (k == 0) return depth[0];
    const double f = (target - force[k - 1]) / (force[k] - force[k - 1]);
    return depth[k - 1] + f * (depth[k] - depth[k - 1]);
  }
  return NAN;
}

double full_width_half_maximum(const std::vector<double>& s, const std::vector<double>& y) {
  if (y.empty()) return 0;
  const std::size_t peak = std::size_t(std::max_element(y.begin(), y.end()) - y.begin());
  const double half = 0.5 * y[peak];
  if (!(y[peak] > 0)) return 0;
  const auto crossing = [&](std::size_t from, std::size_t to) {  // neighbours: y[from] ≥ half > y[to]
    return s[from] + (half - y[from]) / (y[to] - y[from]) * (s[to] - s[from]);
  };
  double left = s.front(), right = s.back();
  for (std::size_t k = peak; k > 0; --k)
    if (y[k - 1] < half) {
      left = crossing(k, k - 1);
      break;
    }
  for (std::size_t k = peak; k + 1 < y.size(); ++k)
    if (y[k + 1] < half) {
      right = crossing(k, k + 1);
      break;
    }
  return std::abs(right - left);
}

}  // namespace vb
