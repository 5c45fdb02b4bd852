#include "engine/bench/gather_floor.hpp"

#include <string>

#include "engine/bench/paced_timing.hpp"
#include "engine/sim/kernel_tables.hpp"
#include "engine/sim/padded_grid.hpp"
#include "engine/sim/step_work_group.hpp"

namespace vb::bench {
namespace {

template <typename T>
cl::Buffer upload(const ClContext& cl, const std::vector<T>& data) {
  return cl::Buffer(cl.context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, data.size() * sizeof(T),
                    const_cast<T*>(data.data()));
}

}  // namespace

GatherFloor::GatherFloor(const ClContext& cl, const Lattice& lattice, const std::vector<double>& inverse_mass,
                         std::size_t work_group, bool reverse, std::size_t block, bool dashpots)
    : cl_(cl), n_(lattice.element_count()) {
  const PaddedGrid grid = make_padded_grid(lattice);
  // Distinct words per element (the tests follow each neighbour's); u.w the inverse mass, as in
  // the step, whose held elements (w = 0) are not stepped.
  std::vector<cl_float> u(4 * n_), v(4 * n_), E(n_);
  for (std::size_t e = 0; e < n_; ++e) {
    const float x = float(e);
    u[4 * e] = 1e-6f * x, u[4 * e + 1] = 2e-6f * x + 1, u[4 * e + 2] = -3e-6f * x, u[4 * e + 3] = float(inverse_mass[e]);
    v[4 * e] = 5e-7f * x + 2, v[4 * e + 1] = -7e-7f * x, v[4 * e + 2] = 1.1e-6f * x + 3, v[4 * e + 3] = 0;
    E[e] = -3000.0f - x;  // negative: the short loop's mark
  }
  u_ = upload(cl, u);
  v_ = upload(cl, v);
  u_pred_ = cl::Buffer(cl.context, CL_MEM_READ_WRITE, 4 * sizeof(cl_float) * n_);
  v_pred_ = cl::Buffer(cl.context, CL_MEM_READ_WRITE, 2 * sizeof(cl_float) * n_);
  grid_ = upload(cl, grid.element_of_cell);
  cell_of_ = upload(cl, grid.cell_of_element);
  E_ = upload(cl, E);
  cl::Program p = build_program(cl, {"common.cl", "gather_floor.cl"}, lattice_tables_source(),
                                  "-DVB_DOUBLE=0 -DVB_FLOOR_DASHPOT=" + std::to_string(int(dashpots)));
  predict_ = cl::Kernel(p, "gather_floor_predict");
  correct_ = cl::Kernel(p, "gather_floor_correct");
  // both kernels: u, v, grid, cell_of, E, sy, sz, u_pred, v_pred, n; the corrector's order after them
  for (cl::Kernel* k : {&predict_, &correct_}) {
    int a = 0;
    for (const cl::Buffer* b : {&u_, &v_, &grid_, &cell_of_, &E_}) k->setArg(a++, *b);
    k->setArg(a++, cl_int(grid.stride_y));
    k->setArg(a++, cl_int(grid.stride_z));
    for (const cl::Buffer* b : {&u_pred_, &v_pred_}) k->setArg(a++, *b);
    k->setArg(a++, cl_uint(n_));
  }
  correct_.setArg(10, cl_int(reverse));
  correct_.setArg(11, cl_uint(std::max<std::size_t>(1, block)));
  // as the step (Simulator's step range): whole groups, of 128 where the device chooses their size
  const std::size_t round = work_group ? work_group : kStepWorkGroup;
  global_ = cl::NDRange((n_ + round - 1) / round * round);
  if (work_group) local_ = cl::NDRange(work_group);
}

std::size_t GatherFloor::device_bytes(const Lattice& lattice) {
  // u, v: 4 words; the packed stage: 6; cell and E: 1 each; the padded grid: 1 per cell
  return lattice.element_count() * 12 * sizeof(cl_float) + padded_grid_shape(lattice).cells * sizeof(cl_int);
}

void GatherFloor::enqueue_predict() { cl_.queue.enqueueNDRangeKernel(predict_, cl::NullRange, global_, local_); }

void GatherFloor::enqueue_correct() { cl_.queue.enqueueNDRangeKernel(correct_, cl::NullRange, global_, local_); }

void GatherFloor::enqueue_steps(std::int64_t steps) {
  for (std::int64_t s = 0; s < steps; ++s) {
    enqueue_predict();
    enqueue_correct();
  }
}

double GatherFloor::steps_per_s(double target_s) {
  enqueue_steps(1);
  cl_.queue.finish();
  return paced_steps_per_s(cl_.queue, [&](std::int64_t steps) { enqueue_steps(steps); }, target_s);
}

std::vector<cl_uint> GatherFloor::read(const cl::Buffer& b, std::size_t words) const {
  std::vector<cl_uint> out(words * n_);
  cl_.queue.enqueueReadBuffer(b, CL_TRUE, 0, out.size() * sizeof(cl_uint), out.data());
  return out;
}

}  // namespace vb::bench
