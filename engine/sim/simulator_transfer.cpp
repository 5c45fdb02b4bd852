// The state between host and device: world-frame n×3 vectors on the host, real4 in the lattice
// frame on the device (the inverse mass in u.w).
#include "engine/sim/simulator.hpp"

#include <algorithm>
#include <cmath>

#include "engine/error.hpp"
#include "engine/sim/kernel_arg_layout.hpp"

namespace vb {
namespace {

template <typename T>
std::vector<T> pack4(const std::vector<double>& xyz, const std::vector<double>* w) {
  const std::size_t n = xyz.size() / 3;
  std::vector<T> out(4 * n);
  for (std::size_t e = 0; e < n; ++e) {
    for (int c = 0; c < 3; ++c) out[4 * e + c] = static_cast<T>(xyz[3 * e + c]);
    out[4 * e + 3] = w ? static_cast<T>((*w)[e]) : T(0);
  }
  return out;
}

template <typename T>
void unpack4(const std::vector<T>& in, std::vector<double>& xyz) {
  const std::size_t n = in.size() / 4;
  xyz.resize(3 * n);
  for (std::size_t e = 0; e < n; ++e)
    for (int c = 0; c < 3; ++c) xyz[3 * e + c] = static_cast<double>(in[4 * e + c]);
}

}  // namespace

std::vector<double> Simulator::read_reals(const cl::Buffer& buffer, std::size_t count) const {
  std::vector<double> out(count);
  if (precision_ == Precision::Double) {
    cl_.queue.enqueueReadBuffer(buffer, CL_TRUE, 0, count * sizeof(double), out.data());
  } else {
    std::vector<float> f(count);
    cl_.queue.enqueueReadBuffer(buffer, CL_TRUE, 0, count * sizeof(float), f.data());
    std::copy(f.begin(), f.end(), out.begin());
  }
  return out;
}

template <typename T>
void Simulator::read_xyz(const cl::Buffer& buffer, std::vector<double>& world) const {
  std::vector<T> data(4 * n_);
  cl_.queue.enqueueReadBuffer(buffer, CL_TRUE, 0, data.size() * sizeof(T), data.data());
  unpack4(data, world);
  for (std::size_t e = 0; e < n_; ++e) {
    const Vec3 w = lattice_.rotation * Vec3(world[3 * e], world[3 * e + 1], world[3 * e + 2]);
    for (int c = 0; c < 3; ++c) world[3 * e + c] = w[c];
  }
}

template <typename T>
void Simulator::write_xyz(const cl::Buffer& buffer, const std::vector<double>& world, const std::vector<double>* w) const {
  auto data = pack4<T>(to_lattice_frame(world), w);
  cl_.queue.enqueueWriteBuffer(buffer, CL_TRUE, 0, data.size() * sizeof(T), data.data());
}

std::vector<double> Simulator::to_lattice_frame(const std::vector<double>& world) const {
  std::vector<double> out(world.size());
  const Eigen::Matrix3d Rt = lattice_.rotation.transpose();
  for (std::size_t e = 0; e < world.size() / 3; ++e) {
    const Vec3 x = Rt * Vec3(world[3 * e], world[3 * e + 1], world[3 * e + 2]);
    for (int c = 0; c < 3; ++c) out[3 * e + c] = x[c];
  }
  return out;
}

void Simulator::download(std::vector<double>& u, std::vector<double>& v) const {
  check_grid_barriers();  // a state the persistent step left invalid is never handed out
  apply_pending_projection();
  if (precision_ == Precision::Double) {
    read_xyz<double>(u_, u);
    read_xyz<double>(v_, v);
  } else {
    read_xyz<float>(u_, u);
    read_xyz<float>(v_, v);
  }
}

void Simulator::upload(const std::vector<double>& u, const std::vector<double>& v) {
  require(u.size() == 3 * n_ && v.size() == 3 * n_, "state size does not match the model");
  pending_ = false;  // the new state replaces the one the projection was for
  // nor is the lagged multiplier that of the new state: start it at zero (all-zero bytes; the
  // constructor's upload comes before the buffer, which starts at zero)
  if (plan_.volume_lag && vol_scalars_())
    cl_.queue.enqueueFillBuffer(vol_scalars_, cl_uchar(0), std::size_t(kVolumeScalars - 1) * real_size_, real_size_);
  if (precision_ == Precision::Double) {
    write_xyz<double>(u_, u, &inverse_mass_);
    write_xyz<double>(v_, v, nullptr);
  } else {
    write_xyz<float>(u_, u, &inverse_mass_);
    write_xyz<float>(v_, v, nullptr);
  }
  if (plan_.lanes || plan_.step_list) mirror_state();
  if (relax_) {
    held_u_.clear();
    for (std::size_t e = 0; e < n_; ++e)
      if (inverse_mass_[e] == 0) held_u_.insert(held_u_.end(), {u[3 * e], u[3 * e + 1], u[3 * e + 2]});
    update_relax_from_rest();
    relax_prev_valid_ = false;  // relax_prev_ holds a state before this one, of another run
  }
}

void Simulator::mirror_state() {
  cl_.queue.enqueueCopyBuffer(u_, u_tmp_, 0, 0, 4 * real_size_ * n_);
  cl_.queue.enqueueCopyBuffer(v_, v_tmp_, 0, 0, 4 * real_size_ * n_);
}

std::vector<double> Simulator::lattice_forces() {
  cl::Kernel k(program_, "lattice_forces");
  cl::Buffer f(cl_.context, CL_MEM_WRITE_ONLY, 4 * real_size_ * n_);
  k.setArg(0, u_);
  k.setArg(1, v_);
  set_lattice_args(k, 2);
  k.setArg(2 + kLatticeArgs, f);
  k.setArg(3 + kLatticeArgs, cl_uint(n_));
  apply_pending_projection();
  enqueue_stress(u_);
  enqueue(k);
  std::vector<double> out;
  if (precision_ == Precision::Double) read_xyz<double>(f, out); else read_xyz<float>(f, out);
  return out;
}

}  // namespace vb
