#pragma once
/// When Heun's corrector steps the elements' aligned blocks from the last to the first by default
/// (VB_CORRECT_REVERSE, kernels/integrate.cl): on GPUs from 1,000,000 elements, without the volume
/// constraint. The predictor walks the elements first to last, so the corrector then starts on the
/// predicted stage's most recently written lines and ends on the elements the next predictor reads
/// first. Measured on the H200 (docs/PERFORMANCE.md, "Work-group sizes"), linear cubes: +4–5% at 1.0M and
/// 1.5M, +2.5% at 4.1M, level at 512k (its DRAM reads fall by ~45%, but DRAM does not bound that
/// step: Nsight Compute) and 3% slower at 262k (not known why);
/// two-term Ogden +0.5%, and with the volume constraint level.
#include <cstddef>

namespace vb {

constexpr std::size_t kCorrectReverseFrom = 1000000;

constexpr bool default_correct_reverse(bool gpu, std::size_t elements, bool volume) {
  return gpu && elements >= kCorrectReverseFrom && !volume;
}

}  // namespace vb
