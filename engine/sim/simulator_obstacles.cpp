// What the tissue meets: indenters, the torus device's rings and contact with the surface's
// triangles, as the kernels' obstacle table and contact buffers (kernels/common.cl, device_contact.cl,
// kernels/triangle_contact.cl).
#include "engine/sim/simulator.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "engine/device/torus.hpp"
#include "engine/error.hpp"
#include "engine/sim/kernel_arg_layout.hpp"
#include "engine/sim/triangle_contact.hpp"
#include "engine/surface/surface_area.hpp"

namespace vb {

Vec3 Simulator::indenter_position(std::size_t i, double t) const {
  const std::vector<PathKnot>& path = scene_.indenters.at(i).path;
  if (path.empty()) return motion_.at(i).position_m(t);
  if (t <= path.front().time_s) return path.front().position_m;
  for (std::size_t k = 0; k + 1 < path.size(); ++k)
    if (t < path[k + 1].time_s) {
      const double f = (t - path[k].time_s) / (path[k + 1].time_s - path[k].time_s);
      return path[k].position_m + f * (path[k + 1].position_m - path[k].position_m);
    }
  return path.back().position_m;
}

std::vector<double> Simulator::indenter_row(std::size_t i) const {
  const IndenterSpec& ind = scene_.indenters[i];
  const IndenterMotion& m = motion_[i];
  const Eigen::Matrix3d Rt = lattice_.rotation.transpose();
  std::vector<double> row(kIndenterStride, 0.0);
  const Vec3 start = Rt * m.start_m, normal = Rt * ind.normal, velocity = Rt * m.velocity_m_s;
  for (int c = 0; c < 3; ++c) row[c] = start[c], row[4 + c] = normal[c], row[8 + c] = velocity[c];
  row[3] = ind.kind == IndenterSpec::Kind::Plate ? -1.0 : ind.radius_m;
  row[12] = std::isfinite(m.travel_time_s) ? m.travel_time_s : 1e300;
  row[13] = double(int(ind.contact));  // 0 push, 1 slide, 2 stick
  row[14] = double(int(ind.kind));     // 0 sphere, 1 plate, 2 cylinder, 3 capsule
  row[15] = ind.length_m;
  row[16] = m.t0_s;
  row[17] = ind.friction;  // Coulomb μ (push contact)
  row[18] = ind.contact_surface == IndenterSpec::Surface::Triangles ? 1.0 : 0.0;
  row[19] = contact_stiffness_n_m_.at(i);  // the penalty of triangle contact (N/m)
  return row;
}

IndenterMotion Simulator::starting_motion(const IndenterSpec& ind) {
  if (!ind.path.empty()) return {ind.path.front().position_m, Vec3::Zero(), 0.0, 0.0};  // follow_paths moves it
  return {ind.start_m, ind.velocity_m_s, 0.0, ind.travel_time_s};
}

void Simulator::set_indenter_motion(std::size_t i, const IndenterMotion& motion) {
  require(i < scene_.indenters.size(), "no indenter " + std::to_string(i) + " in the scene", "indenter");
  motion_[i] = motion;
  const std::vector<double> row = indenter_row(i);
  const std::size_t offset = kIndenterStride * i * real_size_;
  if (precision_ == Precision::Double) {
    cl_.queue.enqueueWriteBuffer(indenters_, CL_TRUE, offset, row.size() * sizeof(double), row.data());
  } else {
    std::vector<float> f(row.size());
    for (std::size_t k = 0; k < row.size(); ++k) f[k] = float(std::clamp(row[k], -3e38, 3e38));
    cl_.queue.enqueueWriteBuffer(indenters_, CL_TRUE, offset, f.size() * sizeof(float), f.data());
  }
}

void Simulator::follow_paths(double t) {
  for (std::size_t i = 0; i < scene_.indenters.size(); ++i) {
    const std::vector<PathKnot>& path = scene_.indenters[i].path;
    if (path.size() < 2) continue;
    std::size_t k = 0;  // the last segment starting at or before t (the first before the path starts)
    while (k + 2 < path.size() && path[k + 1].time_s <= t) ++k;
    if (k == path_segment_[i]) continue;
    path_segment_[i] = k;
    const double span = path[k + 1].time_s - path[k].time_s;
    set_indenter_motion(i, {path[k].position_m, (path[k + 1].position_m - path[k].position_m) / span,
                            path[k].time_s, span});
  }
}

std::size_t Simulator::torus_table_base() const {
  return kIndenterStride * std::max<std::size_t>(1, scene_.indenters.size());
}

std::vector<double> Simulator::obstacle_table() const {
  // Rows in the lattice frame (kernels/common.cl, VB_INDENTER_PARAMS); a placeholder row if none.
  std::vector<double> table(torus_table_base(), 0.0);
  const Eigen::Matrix3d Rt = lattice_.rotation.transpose();
  for (std::size_t i = 0; i < scene_.indenters.size(); ++i) {
    const std::vector<double> row = indenter_row(i);
    std::copy(row.begin(), row.end(), table.begin() + kIndenterStride * i);
  }
  // Torus rows (kernels/device_contact.cl), then each torus's knots: time, minor and major
  // radius, and for the segment to the next knot 1/span and the two rates (0 for the last).
  const std::size_t knots_base = table.size() + kTorusStride * scene_.tori.size();
  table.resize(knots_base, 0.0);
  for (std::size_t i = 0; i < scene_.tori.size(); ++i) {
    const TorusSpec& t = scene_.tori[i];
    double* row = &table[torus_table_base() + kTorusStride * i];
    const Vec3 centre = Rt * t.center_m, axis = Rt * t.axis, perpendicular = Rt * reference_perpendicular(t.axis);
    for (int c = 0; c < 3; ++c) row[c] = centre[c], row[4 + c] = axis[c], row[8 + c] = perpendicular[c];
    row[3] = t.friction;
    row[7] = double(t.schedule.size());
    row[11] = double(table.size());
    for (std::size_t j = 0; j < t.schedule.size(); ++j) {
      const TorusKnot& k = t.schedule[j];
      double inverse_span = 0, minor_rate = 0, major_rate = 0;
      if (j + 1 < t.schedule.size()) {
        const TorusKnot& next = t.schedule[j + 1];
        inverse_span = 1 / (next.time_s - k.time_s);
        minor_rate = (next.minor_radius_m - k.minor_radius_m) * inverse_span;
        major_rate = (next.major_radius_m - k.major_radius_m) * inverse_span;
      }
      table.insert(table.end(), {k.time_s, k.minor_radius_m, k.major_radius_m, inverse_span, minor_rate, major_rate});
    }
  }
  require(table.size() < (1u << 24), "the device's inflation schedules are too long", "device.torus");  // exact in float
  return table;
}

void Simulator::set_indenter_args(cl::Kernel& k, int a, double t_force, double t_project) {
  k.setArg(a, indenters_);
  set_indenter_times(k, a, t_force, t_project);
}

void Simulator::set_indenter_times(cl::Kernel& k, int a, double t_force, double t_project) {
  set_real(k, a + 1, t_force);
  set_real(k, a + 2, t_project);
}

void Simulator::make_contact_area_buffer() {
  // Rest shares: contact happens on the surface, and a share changes little with the deformation.
  const SurfaceMesh built = volume_ ? SurfaceMesh{} : build_surface(lattice_);
  const SurfaceMesh& mesh = volume_ ? surface_ : built;
  contact_area_host_ = element_surface_area_m2(mesh, element_positions_m(lattice_));
  contact_area_ = make_real_buffer(contact_area_host_);
  check_.setArg(kCheckVolume + (volume_ ? 2 : 0), contact_area_);
}

void Simulator::make_triangle_contact_buffers() {
  const TriangleContactMesh m = triangle_contact_mesh(surface_, n_);
  const auto flags_ro = CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR;
  const auto buffer = [&](auto& v) {
    return cl::Buffer(cl_.context, flags_ro, v.size() * sizeof(v[0]), const_cast<void*>(static_cast<const void*>(v.data())));
  };
  tri_elements_ = buffer(m.triangles);
  tri_start_ = buffer(m.start);
  tri_corner_ = buffer(m.corner);
  const std::size_t corners = 3 * tri_triangles_ * std::max<std::size_t>(1, scene_.indenters.size());
  std::vector<char> zeros(corners * 4 * real_size_, 0);
  corner_force_ = cl::Buffer(cl_.context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, zeros.size(), zeros.data());

  // kernels/triangle_contact.cl: u, cell_of, sy, sz, origin, h, triangles, count, frame sign,
  // indenters, t, corner forces
  tri_kernel_ = cl::Kernel(program_, "triangle_contact");
  tri_kernel_.setArg(1, cell_);
  tri_kernel_.setArg(2, cl_int(stride_y_));
  tri_kernel_.setArg(3, cl_int(stride_z_));
  set_world_vector(tri_kernel_, 4, lattice_.origin_m);
  set_real(tri_kernel_, 5, lattice_.spacing_m);
  tri_kernel_.setArg(6, tri_elements_);
  tri_kernel_.setArg(7, cl_uint(tri_triangles_));
  set_real(tri_kernel_, 8, lattice_.rotation.determinant() < 0 ? -1.0 : 1.0);  // outward in the lattice frame
  tri_kernel_.setArg(9, indenters_);
  tri_kernel_.setArg(11, corner_force_);
  for (cl::Kernel* k : {&euler_, &predict_, &correct_, &relax_kernel_, &check_}) {
    if (!(*k)()) continue;
    // VB_TRI_PARAMS, last but for the stepping kernels' state arena
    const int first = int(k->getInfo<CL_KERNEL_NUM_ARGS>()) - kTriangleArgs - (k == &check_ ? 0 : 1);
    k->setArg(first + 0, corner_force_);
    k->setArg(first + 1, tri_start_);
    k->setArg(first + 2, tri_corner_);
    k->setArg(first + 3, cl_uint(tri_triangles_));
  }
}

void Simulator::enqueue_triangle_contact(const cl::Buffer& u, double t_s) {
  if (!tri_contact_) return;
  tri_kernel_.setArg(0, u);
  set_real(tri_kernel_, 10, t_s);
  const std::size_t wg = kCheckWorkGroup;
  launch(tri_kernel_, cl::NDRange((tri_triangles_ + wg - 1) / wg * wg), cl_.info.is_gpu ? cl::NDRange(wg) : cl::NullRange);
}

std::vector<double> Simulator::triangle_contact_forces_n() {
  require(tri_contact_, "no indenter of the scene uses contact_surface = \"triangles\"", "indenter");
  enqueue_triangle_contact(u_, time_s());
  const std::size_t count = 4 * 3 * tri_triangles_ * std::max<std::size_t>(1, scene_.indenters.size());
  const std::vector<double> raw = read_reals(corner_force_, count);
  std::vector<double> out(3 * (count / 4));
  for (std::size_t k = 0; k < count / 4; ++k) {
    const Vec3 w = lattice_.rotation * Vec3(raw[4 * k], raw[4 * k + 1], raw[4 * k + 2]);
    for (int c = 0; c < 3; ++c) out[3 * k + c] = w[c];
  }
  return out;
}

}  // namespace vb
