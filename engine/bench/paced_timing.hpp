#pragma once
/// Timing of device work enqueued in batches of steps, with the queue kept short (the bench's
/// step rates: apps/bench_throughput.cpp, engine/bench/gather_floor.hpp).
#include <CL/opencl.hpp>
#include <cstdint>
#include <functional>

namespace vb::bench {

/// Enqueues `steps` steps by `advance(count)` in chunks of 32; after each chunk it waits for the one
/// two chunks back, so that the queue never holds more than three chunks. A run issues at most
/// check_every steps before it reads back; thousands of steps at once fill NVIDIA's queue, and the
/// host blocked inside the driver then leaves gaps between launches (~20 µs per step at 1.5M
/// elements) that no run has.
void advance_paced(const cl::CommandQueue& queue, const std::function<void(std::int64_t)>& advance, std::int64_t steps);

/// Steps per second of `advance`, timed over enough steps to last about `target_s` (batches
/// growing from 4 steps; the caller warms up first).
double paced_steps_per_s(const cl::CommandQueue& queue, const std::function<void(std::int64_t)>& advance, double target_s);

}  // namespace vb::bench
