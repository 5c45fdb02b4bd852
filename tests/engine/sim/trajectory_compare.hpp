#pragma once
// Comparing two runs of the same scene that should agree to rounding (two ways of launching the
// same kernels): u then v, flattened.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace vb::test {

/// Largest difference of `got` from `ref` over the largest |value| of `ref`; fails the test on a
/// size mismatch, a non-finite value of `got` or an all-zero `ref` (nothing moved: nothing tested).
inline double relative_difference(const std::vector<double>& got, const std::vector<double>& ref) {
  EXPECT_EQ(got.size(), ref.size());
  double largest = 0, diff = 0;
  for (std::size_t i = 0; i < got.size() && i < ref.size(); ++i) {
    EXPECT_TRUE(std::isfinite(got[i]));
    largest = std::max(largest, std::abs(ref[i]));
    diff = std::max(diff, std::abs(got[i] - ref[i]));
  }
  EXPECT_GT(largest, 0);
  return diff / largest;
}

}  // namespace vb::test
