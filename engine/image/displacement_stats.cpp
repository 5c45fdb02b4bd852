#include "engine/image/displacement_stats.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vb {

DisplacementStats displacement_stats(const std::vector<float>& u) {
  DisplacementStats s;
  const std::size_t n = u.size() / 3;
  if (n == 0) return s;
  s.min_mm.fill(std::numeric_limits<double>::infinity());
  s.max_mm.fill(-std::numeric_limits<double>::infinity());
  std::array<double, 3> sum{}, sum_abs{};
  double sum_length = 0;
  for (std::size_t v = 0; v < n; ++v) {
    double squared = 0;
    for (int c = 0; c < 3; ++c) {
      const double mm = 1e3 * double(u[3 * v + std::size_t(c)]);
      s.min_mm[c] = std::min(s.min_mm[c], mm);
      s.max_mm[c] = std::max(s.max_mm[c], mm);
      sum[c] += mm;
      sum_abs[c] += std::abs(mm);
      squared += mm * mm;
    }
    const double length = std::sqrt(squared);
    sum_length += length;
    s.max_length_mm = std::max(s.max_length_mm, length);
  }
  for (int c = 0; c < 3; ++c) {
    s.mean_mm[c] = sum[c] / double(n);
    s.mean_abs_mm[c] = sum_abs[c] / double(n);
  }
  s.mean_length_mm = sum_length / double(n);
  return s;
}

}  // namespace vb
