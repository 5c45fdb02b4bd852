// The persistent Heun step (kernels/persistent.cl): its kernel's arguments, its launches, and the
// check that its grid barriers never timed out.
#include <iostream>
#include <string>

#include "engine/error.hpp"
#include "engine/sim/kernel_arg_layout.hpp"
#include "engine/sim/persistent_step.hpp"
#include "engine/sim/simulator.hpp"

namespace vb {
namespace {

// heun_step_persistent's arguments (kernels/persistent.cl): u, v, ũ, ṽ, the lattice, the
// obstacles, t0, t1, dt, n, rest frames (the stepping kernels' layout, kernel_arg_layout.hpp, up to
// dt); with the volume constraint 10 more; then sync, target.
constexpr int kLattice = kStepLattice, kIndenters = kStepIndenter, kDt = kIndenters + kIndenterArgs, kRestFrame = kDt + 2;
constexpr int kMesh = kRestFrame + 1, kRestVolume = kMesh + 7, kProject = kMesh + 9;
constexpr int kSyncWords = 2 + 12;  // count, fault flag, VB_PERSISTENT_TRACE's stamps (≤ 9 barriers + 2)
/// the sync buffer's argument; the launch's first barrier target follows it
constexpr int sync_arg(bool volume) { return volume ? kProject + 1 : kMesh; }

}  // namespace

void Simulator::make_persistent_kernel() {
  cl::Kernel& k = persistent_kernel_ = cl::Kernel(program_, "heun_step_persistent");
  // Every group must be resident at once: the build log says how many registers the kernel
  // really uses (docs/PERFORMANCE.md, "GPU-only guards").
  plan_.persistent.fit_registers(
      registers_in_build_log(program_.getBuildInfo<CL_PROGRAM_BUILD_LOG>(cl_.info.device), "heun_step_persistent"),
      cl_.info.compute_units);
  k.setArg(0, u_);
  k.setArg(1, v_);
  k.setArg(2, u_tmp_);
  k.setArg(3, v_tmp_);
  set_lattice_args(k, kLattice);
  set_indenter_args(k, kIndenters, 0.0, 0.0);
  k.setArg(kDt + 1, cl_uint(n_));  // kDt: set_persistent_time_step
  k.setArg(kRestFrame, rest_frame_);
  if (volume_) {
    k.setArg(kMesh, vol_mesh_.buffer());
    k.setArg(kMesh + 1, vol_mesh_at_);
    k.setArg(kMesh + 2, cl_uint(volume_surface_));
    set_world_vector(k, kMesh + 3, vol_centre_);
    k.setArg(kMesh + 4, vol_grad_);
    k.setArg(kMesh + 5, vol_partial_);
    k.setArg(kMesh + 6, cl_uint(volume_groups_));
    k.setArg(kMesh + 8, vol_scalars_);
    set_rest_volume_args();  // V0 (kRestVolume), where every projecting kernel gets it
  }
  const cl_uint zeros[kSyncWords] = {};  // barrier count, fault flag, trace stamps
  grid_sync_ = cl::Buffer(cl_.context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, sizeof zeros, const_cast<cl_uint*>(zeros));
  k.setArg(sync_arg(volume_), grid_sync_);
}

void Simulator::set_persistent_rest_volume(double v0) { set_real(persistent_kernel_, kRestVolume, v0); }

void Simulator::set_persistent_time_step() { set_real(persistent_kernel_, kDt, dt_.dt_s); }

void Simulator::enqueue_persistent_step(double t0_s, double t1_s, bool moving_obstacles, bool project) {
  cl::Kernel& k = persistent_kernel_;
  if (moving_obstacles) {  // the stage times (the obstacle table is set once)
    set_real(k, kIndenters + 1, t0_s);
    set_real(k, kIndenters + 2, t1_s);
  }
  if (volume_) k.setArg(kProject, cl_int(project));
  k.setArg(sync_arg(volume_) + 1, sync_start_);
  launch(k, cl::NDRange(plan_.persistent.groups * PersistentPlan::kWorkGroup), cl::NDRange(PersistentPlan::kWorkGroup));
  // the kernel's grid barriers: 2 around the stress passes, 1 after the predictor, 4 per projection
  const cl_uint barriers = cl_uint(1 + (hyper_ ? 2 : 0) + (project ? 4 : 0));
  sync_start_ += barriers * cl_uint(plan_.persistent.groups);  // wraps as the kernel's count does
}

void Simulator::check_grid_barriers() const {
  if (!plan_.persistent.on) return;
  cl_uint sync[kSyncWords] = {};
  cl_.queue.enqueueReadBuffer(grid_sync_, CL_TRUE, 0, sizeof sync, sync);
  if (plan_.persistent.trace) {  // ns between group 0's stamps of the last launch: pass by pass
    std::cerr << "persistent step, " << plan_.persistent.groups << " groups, last launch's passes (us):";
    for (int k = 3; k < kSyncWords && sync[k] != 0; ++k) std::cerr << ' ' << 1e-3 * double(sync[k] - sync[k - 1]);
    std::cerr << '\n';
  }
  require(sync[1] == 0,
          "the persistent Heun step's work-groups were not all resident on the device (a grid barrier timed out), "
          "so the state is not valid",
          "device", "the one-launch step does not fit this device: report it with the output of `voxbreast info`");
  // Each launch's targets start from the count the host predicts (enqueue_persistent_step): a
  // barrier count the host and the kernel disagree on would let groups pass barriers early.
  require(sync[0] == sync_start_,
          "the persistent Heun step's barrier count (" + std::to_string(sync[0]) + ") is not the expected " +
              std::to_string(sync_start_) + ", so its passes may have overlapped and the state is not valid",
          "device", "the one-launch step does not fit this device: report it with the output of `voxbreast info`");
}

}  // namespace vb
