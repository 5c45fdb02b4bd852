#pragma once
/// The gather floor (kernels/gather_floor.cl): Heun's two stepping kernels of the GPUs' plain path
/// (linear springs on the short connection loop, the predicted stage packed) with their connection
/// arithmetic taken out, on a model's own lattice and in the step's work-group size and order. Its
/// rate is the step's with only the memory reads and writes left: the bench states the step's
/// rate as a fraction of it beside the fraction of copy bandwidth (docs/BENCHMARKS.md).
#include <CL/opencl.hpp>
#include <cstdint>
#include <vector>

#include "engine/lattice/lattice.hpp"
#include "engine/sim/opencl_runtime.hpp"

namespace vb::bench {

class GatherFloor {
 public:
  /// `inverse_mass`: per element, 0 for held ones (the step does not step them). `work_group`: the
  /// step's (0: the device's choice). `reverse`: the corrector over blocks of `block` elements
  /// from the last to the first (Simulator::correct_reverse). `dashpots`: the step has connection
  /// dashpots (solver.dashpot_ratio > 0), so it reads the neighbours' velocities too.
  GatherFloor(const ClContext& cl, const Lattice& lattice, const std::vector<double>& inverse_mass,
              std::size_t work_group, bool reverse, std::size_t block, bool dashpots);

  /// Device memory the floor allocates for `lattice` (its own state, stage, grid and E).
  static std::size_t device_bytes(const Lattice& lattice);

  void enqueue_predict();
  void enqueue_correct();
  void enqueue_steps(std::int64_t steps);
  /// Floor steps per second over about `target_s` (after a warm-up step).
  double steps_per_s(double target_s);

  /// The arrays as they are now (each element's 4 or 2 float words), for tests.
  std::vector<cl_uint> read_u() const { return read(u_, 4); }
  std::vector<cl_uint> read_v() const { return read(v_, 4); }
  std::vector<cl_uint> read_u_pred() const { return read(u_pred_, 4); }
  std::vector<cl_uint> read_v_pred() const { return read(v_pred_, 2); }
  std::vector<cl_uint> read_modulus() const { return read(E_, 1); }

 private:
  std::vector<cl_uint> read(const cl::Buffer& b, std::size_t words) const;

  const ClContext& cl_;
  std::size_t n_ = 0;
  cl::Buffer u_, v_, u_pred_, v_pred_, grid_, cell_of_, E_;
  cl::Kernel predict_, correct_;
  cl::NDRange global_, local_;
};

}  // namespace vb::bench
