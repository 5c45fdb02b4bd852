#pragma once
/// Items of uneven cost (image slices, compressed blocks) spread over the host's cores, each
/// thread taking the next item as it finishes one.
#include <atomic>
#include <cstddef>

#include "engine/sim/parallel_chunks.hpp"

namespace vb {

/// Calls fn(index) for every index of [0, n), one core per thread, each thread taking the next
/// index as it finishes one (items of uneven cost balance out). After each of its items the
/// calling thread calls on_done(items finished so far): progress reports come from one thread
/// only. fn must not throw; it must not depend on which thread runs it.
template <class Fn, class Done>
void for_each_index_dynamic(std::size_t n, Fn fn, Done on_done) {
  std::atomic<std::size_t> next{0}, finished{0};
  for_chunks(n, chunk_count(n, 1), [&](std::size_t chunk, std::size_t, std::size_t) {
    for (std::size_t i = next++; i < n; i = next++) {
      fn(i);
      const std::size_t done = ++finished;
      if (chunk == 0) on_done(done);
    }
  });
}

}  // namespace vb
