// The volume-preservation constraint's buffers and launches (docs/PHYSICS.md "Volume preservation",
// kernels/volume.cl).
#include "engine/sim/simulator.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "engine/error.hpp"
#include "engine/sim/kernel_arg_layout.hpp"
#include "engine/surface/enclosed_volume.hpp"

namespace vb {

void Simulator::make_volume_buffers(const SurfaceMesh& mesh, const std::vector<cl_uint>& surface,
                                    const std::vector<std::uint32_t>& surface_index) {
  // Triangles as element ids; per surface element the corners (3·triangle + corner) it is in,
  // over all its vertices (an element on a pinch has several).
  std::vector<cl_uint> triangles(3 * mesh.triangles.size()), start(surface.size() + 1, 0), incident;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      triangles[3 * t + c] = mesh.element_of_vertex[mesh.triangles[t][c]];
      ++start[surface_index[triangles[3 * t + c]] + 1];
    }
  for (std::size_t i = 0; i < surface.size(); ++i) start[i + 1] += start[i];
  incident.resize(start.back());
  std::vector<cl_uint> fill(start.begin(), start.end() - 1);
  for (std::size_t k = 0; k < triangles.size(); ++k) incident[fill[surface_index[triangles[k]]]++] = cl_uint(k);
  if (plan_.volume_pairs) {  // per incident corner the triangle's other two corners' elements, in cyclic order
    std::vector<cl_uint> pairs(2 * incident.size());
    for (std::size_t k = 0; k < incident.size(); ++k) {
      const std::size_t t = incident[k] / 3, corner = incident[k] % 3;
      pairs[2 * k] = triangles[3 * t + (corner + 1) % 3];
      pairs[2 * k + 1] = triangles[3 * t + (corner + 2) % 3];
    }
    incident = std::move(pairs);
  }

  frame_sign_ = lattice_.rotation.determinant() < 0 ? -1.0 : 1.0;
  rest_volume_m3_ = double(mesh.complete_cell_count) * std::pow(lattice_.spacing_m, 3);
  Vec3 centre = Vec3::Zero();  // positions are taken relative to it, to keep rounding small
  for (const cl_uint e : surface) centre += lattice_.rest_position(e);
  centre /= double(surface.size());
  vol_centre_ = centre;

  // one buffer for the mesh (device_arena.hpp), slots as kernels/volume.cl's VB_UNPACK_MESH
  vol_mesh_.add(triangles.data(), triangles.size() * sizeof(cl_uint));
  vol_mesh_.add(surface.data(), surface.size() * sizeof(cl_uint));
  vol_mesh_.add(start.data(), start.size() * sizeof(cl_uint));
  vol_mesh_.add(incident.data(), incident.size() * sizeof(cl_uint));
  vol_mesh_.create(cl_);
  for (int i = 0; i < 4; ++i) vol_mesh_at_.s[i] = vol_mesh_.offset_units(std::size_t(i));
  // (the gradient, zero off the surface, the partial sums and the scalars are in the state arena)
  const cl_uint zero = 0;  // volume_project's count of finished work-groups
  vol_done_ = cl::Buffer(cl_.context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, sizeof zero, const_cast<cl_uint*>(&zero));

  // volume_partials and volume_project take the same lattice, mesh, centre and gradient arguments
  // (volume_partials, a step kernel, the gradient as a state arena offset)
  const auto mesh_kernel = [&](const char* name, bool state_offsets) {
    cl::Kernel k(program_, name);
    set_lattice_args(k, 2);
    k.setArg(kVolumeMesh + 0, vol_mesh_.buffer());
    k.setArg(kVolumeMesh + 1, vol_mesh_at_);
    k.setArg(kVolumeMesh + 2, cl_uint(volume_surface_));
    set_world_vector(k, kVolumeCentre, centre);
    if (state_offsets) k.setArg(kVolumeCentre + 1, at(vol_grad_));
    else k.setArg(kVolumeCentre + 1, vol_grad_);
    return k;
  };
  vol_partials_ = mesh_kernel("volume_partials", true);
  vol_partials_.setArg(kVolumeWithForce + 1, at(vol_partial_));
  set_state_arena_arg(vol_partials_);
  vol_finish_ = cl::Kernel(program_, "volume_finish");
  vol_finish_.setArg(0, vol_partial_);
  vol_finish_.setArg(1, cl_uint(volume_groups_));
  vol_finish_.setArg(3, vol_scalars_);
  vol_apply_ = cl::Kernel(program_, "volume_apply");
  vol_apply_.setArg(2, vol_mesh_.buffer());
  vol_apply_.setArg(3, vol_mesh_at_);
  vol_apply_.setArg(4, cl_uint(volume_surface_));
  vol_apply_.setArg(5, at(vol_grad_));
  vol_apply_.setArg(6, at(vol_partial_));
  vol_apply_.setArg(7, cl_uint(volume_groups_));
  vol_apply_.setArg(kApplyRestVolume + 1, at(vol_scalars_));
  set_state_arena_arg(vol_apply_);
  vol_project_ = mesh_kernel("volume_project", false);
  vol_project_.setArg(kProjectGrad + 1, vol_partial_);
  vol_project_.setArg(kProjectRestVolume + 1, vol_scalars_);
  vol_project_.setArg(kProjectRestVolume + 2, vol_done_);
  if (plan_.volume_launches == 0) {
    // the predicted stage's projection has its own gradient and scalars: the state's stays
    // pending for heun_correct's own u, v while the stage's is computed
    // (its gradient and scalars, and zero scalars, are in the state arena)
    device_bytes_ += 4 * real_size_ * n_;
    vol_pending_ = mesh_kernel("volume_pending", false);
    vol_pending_.setArg(kProjectGrad + 1, vol_partial_);
    vol_pending_.setArg(kProjectRestVolume + 2, vol_done_);
    set_fold_args(false, false);
  }
  if (plan_.volume_lag) {  // heun_predict's or relax_step's (and lanes') last arguments before VB_TRI_PARAMS, the arena
    cl::Kernel& k = relax_ ? relax_kernel_ : predict_;
    const int last = int(k.getInfo<CL_KERNEL_NUM_ARGS>()) - (tri_contact_ ? kTriangleArgs : 0) - 1;
    k.setArg(last - 2, at(vol_grad_));
    k.setArg(last - 1, at(vol_scalars_));
  }
  if (relax_) {  // the projection weights by relaxation's masses (kernels/volume.cl, VB_PROJECTION_PARAM)
    const auto from_end = [&](cl::Kernel& k, cl_uint back) { k.setArg(k.getInfo<CL_KERNEL_NUM_ARGS>() - back, relax_scale_); };
    from_end(vol_partials_, 2);  // before the state arena
    from_end(vol_apply_, 2);
    from_end(vol_project_, 1);
  }
  set_rest_volume_args();
  check_.setArg(kCheckVolume, vol_grad_);
  check_.setArg(kCheckVolume + 1, vol_scalars_);
}

void Simulator::set_rest_volume_args() {
  const double v0 = frame_sign_ * rest_volume_m3_;  // lattice frame
  set_real(vol_finish_, 2, v0);
  set_real(vol_apply_, kApplyRestVolume, v0);
  set_real(vol_project_, kProjectRestVolume, v0);
  if (plan_.volume_launches == 0) set_real(vol_pending_, kProjectRestVolume, v0);
  if (persistent_kernel_()) set_persistent_rest_volume(v0);
}

void Simulator::set_fold_args(bool state_pending, bool pred_pending) {
  // kernels/integrate.cl (VB_FOLD_PARAMS): after dt, n the state's gradient and scalars, then
  // (heun_correct) the predicted stage's; zero scalars where nothing is pending
  // (state arena offsets)
  const cl_uint state = at(state_pending ? vol_scalars_ : vol_no_scalars_);
  const cl_uint pred = at(pred_pending ? vol_scalars_pred_ : vol_no_scalars_);
  const int a = kStepIndenter + kIndenterArgs + 2;
  for (cl::Kernel* k : {&predict_, &correct_}) {
    k->setArg(a, at(vol_grad_));
    k->setArg(a + 1, state);
  }
  correct_.setArg(a + 2, at(vol_grad_pred_));
  correct_.setArg(a + 3, pred);
}

void Simulator::enqueue_pending_projection(const cl::Buffer& u, const cl::Buffer& v, bool predicted) {
  vol_pending_.setArg(0, u);
  vol_pending_.setArg(1, v);
  vol_pending_.setArg(kProjectGrad, predicted ? vol_grad_pred_ : vol_grad_);
  vol_pending_.setArg(kProjectRestVolume + 1, predicted ? vol_scalars_pred_ : vol_scalars_);
  launch(vol_pending_, cl::NDRange(volume_groups_ * kCheckWorkGroup), cl::NDRange(kCheckWorkGroup));
}

void Simulator::apply_pending_projection() const {
  if (!pending_) return;
  // volume_apply sums the partials the last volume_pending left (the same λ, μ) and applies them
  pending_ = false;
  vol_apply_.setArg(0, at(u_));
  vol_apply_.setArg(1, at(v_));
  const std::size_t wg = kCheckWorkGroup, global = (volume_surface_ + wg - 1) / wg * wg;
  launch(vol_apply_, cl::NDRange(global), cl::NDRange(wg));
}

void Simulator::enqueue_volume_sums(bool with_force) { enqueue_volume_sums(with_force, u_, v_); }

void Simulator::enqueue_volume_partials(bool with_force, const cl::Buffer& u, const cl::Buffer& v) {
  vol_partials_.setArg(0, at(u));
  vol_partials_.setArg(1, at(v));
  vol_partials_.setArg(kVolumeWithForce, cl_int(with_force));
  launch(vol_partials_, cl::NDRange(volume_groups_ * kCheckWorkGroup), cl::NDRange(kCheckWorkGroup));
}

void Simulator::enqueue_volume_sums(bool with_force, const cl::Buffer& u, const cl::Buffer& v) {
  enqueue_volume_partials(with_force, u, v);
  launch(vol_finish_, cl::NDRange(kCheckWorkGroup), cl::NDRange(kCheckWorkGroup));
}

void Simulator::enqueue_volume_correction(const cl::Buffer& u, const cl::Buffer& v) {
  if (plan_.volume_launches == 1) {  // sums, λ and μ, and the projection in one launch
    vol_project_.setArg(0, u);
    vol_project_.setArg(1, v);
    const std::size_t groups = (volume_surface_ + volume_wg_ - 1) / volume_wg_;
    launch(vol_project_, cl::NDRange(groups * volume_wg_), cl::NDRange(volume_wg_));
    return;
  }
  enqueue_volume_partials(false, u, v);  // volume_apply sums the partials itself: no volume_finish
  vol_apply_.setArg(0, at(u));
  vol_apply_.setArg(1, at(v));
  const std::size_t wg = kCheckWorkGroup, global = (volume_surface_ + wg - 1) / wg * wg;
  launch(vol_apply_, cl::NDRange(global), cl::NDRange(wg));
}

double Simulator::enclosed_volume_m3() {
  require(volume_, "the enclosed volume is computed on the device only with [volume] preserve = true");
  apply_pending_projection();
  enqueue_volume_sums(false);
  return read_enclosed_volume_m3();
}

double Simulator::read_enclosed_volume_m3() const { return frame_sign_ * volume_scalars().volume_m3; }

Simulator::VolumeScalars Simulator::volume_scalars() const {
  require(volume_, "the volume constraint's scalars exist only with [volume] preserve = true");
  const std::vector<double> s = read_reals(vol_scalars_, kVolumeScalars);  // λ, μ, V, p, M (kernels/volume.cl)
  return {s[0], s[1], s[2], s[3], s[4]};
}

std::vector<double> Simulator::volume_gradient_m2() {
  require(volume_, "the volume gradient is computed on the device only with [volume] preserve = true");
  apply_pending_projection();
  enqueue_volume_sums(false);
  std::vector<double> g;
  if (precision_ == Precision::Double) read_xyz<double>(vol_grad_, g); else read_xyz<float>(vol_grad_, g);
  for (double& x : g) x *= frame_sign_;
  return g;
}

}  // namespace vb
