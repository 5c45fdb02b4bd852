#pragma once
/// Host loops over every element split into contiguous chunks on the host's cores: the time-step
/// and mass-scale walks every simulator and every new set of a fit's moduli makes (5 ms per 38.7k
/// elements on one core, 48 ms for a fit's batch of nine copies; docs/FIT.md). Results must not
/// depend on the split: per-element outputs, or reductions (max) that are exact in any order.
#include <algorithm>
#include <cstddef>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace vb {

/// How many chunks [0, n) is split into: one per core, each at least min_per_chunk long (a
/// thread's start, tens of µs, is then under a tenth of its share of the walk; 16,384 left the
/// 38.7k phantom's walk on 2 of the H200 host's 16 cores: docs/PERFORMANCE.md, "Relaxation: mass scaling and host walks").
inline std::size_t chunk_count(std::size_t n, std::size_t min_per_chunk = 4096) {
  const std::size_t cores = std::max(1u, std::thread::hardware_concurrency());
  return std::max<std::size_t>(1, std::min(cores, n / std::max<std::size_t>(1, min_per_chunk)));
}

/// Calls fn(chunk, begin, end) for `chunks` contiguous ranges covering [0, n), chunk 0 on this
/// thread and the others on their own (on this one too where the system has no thread to give).
/// fn must not throw.
template <class Fn>
void for_chunks(std::size_t n, std::size_t chunks, Fn fn) {
  chunks = std::max<std::size_t>(1, chunks);
  auto range = [&](std::size_t c) { return std::pair{n * c / chunks, n * (c + 1) / chunks}; };
  std::vector<std::thread> threads;
  threads.reserve(chunks - 1);
  for (std::size_t c = 1; c < chunks; ++c) {
    try {
      threads.emplace_back([&, c] { fn(c, range(c).first, range(c).second); });
    } catch (const std::system_error&) {
      fn(c, range(c).first, range(c).second);
    }
  }
  fn(std::size_t(0), range(0).first, range(0).second);
  for (std::thread& t : threads) t.join();
}

}  // namespace vb
