#include "engine/bench/paced_timing.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace vb::bench {

void advance_paced(const cl::CommandQueue& queue, const std::function<void(std::int64_t)>& advance, std::int64_t steps) {
  constexpr std::int64_t chunk = 32;
  cl::Event before_last, last;
  for (std::int64_t done = 0; done < steps; done += chunk) {
    advance(std::min(chunk, steps - done));
    if (before_last()) before_last.wait();
    before_last = last;
    queue.enqueueMarkerWithWaitList(nullptr, &last);
    queue.flush();
  }
}

double paced_steps_per_s(const cl::CommandQueue& queue, const std::function<void(std::int64_t)>& advance, double target_s) {
  std::int64_t steps = 4;
  for (;;) {
    const auto t0 = std::chrono::steady_clock::now();
    advance_paced(queue, advance, steps);
    queue.finish();
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (t >= target_s || steps >= (1 << 22)) return double(steps) / t;
    steps = std::int64_t(std::ceil(double(steps) * std::min(8.0, 1.2 * target_s / std::max(t, 1e-6))));
  }
}

}  // namespace vb::bench
