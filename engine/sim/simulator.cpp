#include "engine/sim/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "engine/error.hpp"
#include "engine/sim/correct_order.hpp"
#include "engine/sim/device_memory.hpp"
#include "engine/sim/kernel_arg_layout.hpp"
#include "engine/sim/kernel_tables.hpp"
#include "engine/sim/padded_grid.hpp"
#include "engine/sim/step_list_rule.hpp"
#include "engine/sim/step_work_group.hpp"
#include "engine/sim/triangle_contact.hpp"
#include "engine/sim/uniform_neighbourhood.hpp"
#include "engine/surface/enclosed_volume.hpp"

namespace vb {
namespace {

/// The free elements in ascending order (the lanes kernels' and the step list's work-items).
std::vector<cl_uint> free_elements(const std::vector<double>& inverse_mass) {
  std::vector<cl_uint> list;
  for (std::size_t e = 0; e < inverse_mass.size(); ++e)
    if (inverse_mass[e] != 0) list.push_back(cl_uint(e));
  return list;
}

/// The elements of a surface mesh's vertices, each once in order of first appearance, and each
/// element's place in that list (index_of; kNoSurface off the surface).
constexpr std::uint32_t kNoSurface = 0xffffffffu;
std::vector<cl_uint> mesh_surface_elements(const SurfaceMesh& mesh, std::size_t n, std::vector<std::uint32_t>& index_of) {
  index_of.assign(n, kNoSurface);
  std::vector<cl_uint> surface;
  for (const std::uint32_t e : mesh.element_of_vertex)
    if (index_of[e] == kNoSurface) index_of[e] = std::uint32_t(surface.size()), surface.push_back(e);
  return surface;
}

/// The elements whose element stress some free element reads in a step: the free ones (their own
/// Q) and every neighbour of one (Q·h·d and the hourglass term's C). A held element deep in the
/// held region is read by nobody.
std::vector<cl_uint> elements_read_by_free(const Lattice& lattice, const std::vector<double>& inverse_mass) {
  std::vector<cl_uint> list;
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    bool read = inverse_mass[e] != 0;
    for (const std::int32_t j : lattice.neighbours(e)) read = read || (j >= 0 && inverse_mass[std::size_t(j)] != 0);
    if (read) list.push_back(cl_uint(e));
  }
  return list;
}

}  // namespace

Simulator::Simulator(const Scene& scene, const Lattice& lattice, const ElementArrays& el, const ClContext& cl,
                     const PlanOverrides& overrides)
    : scene_(scene),
      lattice_(lattice),
      cl_(cl),
      precision_(scene.solver.precision),
      n_(lattice.element_count()),
      real_size_(scene.solver.precision == Precision::Double ? sizeof(double) : sizeof(float)),
      inverse_mass_(el.inverse_mass) {
  require(n_ > 0, "the model has no elements", "model");
  require(precision_ == Precision::Float || cl.info.fp64,
          "double precision requested but device '" + cl.info.name + "' has no fp64 support",
          "solver.precision", "use precision = \"float\" or another device");
  dt_ = choose_time_step(scene, lattice, el);
  relax_ = scene.solver.integrator == Integrator::Relaxation;
  damping_ = relax_ ? 0.0 : scene.solver.damping_per_s;  // relaxation: set from the first check on
  gravity_ = scene.gravity.active ? scene.gravity.acceleration_m_s2 : Vec3::Zero();
  require(dt_.dt_s > 0 && std::isfinite(dt_.dt_s), "time step must be positive and finite", "solver.dt");

  // Padded voxel grid: one empty layer on every side, so neighbour lookups never leave it.
  const PaddedGrid shape = padded_grid_shape(lattice);
  stride_y_ = shape.stride_y;
  stride_z_ = shape.stride_z;
  const std::size_t cells = shape.cells;
  require(cells < 0x7fffffffu, "the model's bounding box has too many voxels for 32-bit indexing", "model",
          "downsample or crop the model");

  const std::size_t state_bytes = 4 * real_size_ * n_;
  device_bytes_ = estimated_device_bytes(n_, cells, precision_, el.hyperelastic);
  if (relax_) device_bytes_ += n_ * 9 * real_size_;  // mass scale; u and lattice force at the last check
  volume_ = scene.volume.preserve;
  require(!volume_ || scene.volume.every >= 1, "volume.every must be at least 1", "volume.every");
  // Relaxation reaches the constrained equilibrium only by the lagged pressure of a projection
  // every step (kernels/relax.cl); between sparser projections the surface drifts and is pulled
  // back, so it would never meet its stop (docs/PHYSICS.md, "Volume preservation").
  require(!volume_ || !relax_ || scene.volume.every == 1,
          "relaxation with the volume constraint needs a projection every step (volume.every = " +
              std::to_string(scene.volume.every) + " would never reach equilibrium)",
          "volume.every", "set every = 1, or use integrator = \"heun\"");
  if (volume_) {
    surface_ = build_surface(lattice);
    const SurfaceMesh& mesh = surface_;
    require(!mesh.triangles.empty(), "the model has no closed surface to preserve the volume of", "volume.preserve",
            "the body is the union of complete dual cells (docs/SURFACE.md): it needs parts two elements thick");
    device_bytes_ += estimated_volume_device_bytes(n_, mesh.surface_element_count, mesh.triangles.size(), precision_);
  }
  // Triangle contact (kernels/triangle_contact.cl): the surface mesh and the penalty stiffness.
  check_triangle_contact(scene);
  tri_contact_ = uses_triangle_contact(scene);
  TriangleContactPenalty penalty;
  penalty.stiffness_n_m.assign(scene.indenters.size(), 0.0);
  if (tri_contact_) {
    if (!volume_) surface_ = build_surface(lattice);
    require(!surface_.triangles.empty(), "the model has no closed surface for triangle contact", "indenter",
            "the body is the union of complete dual cells (docs/SURFACE.md): it needs parts two elements thick");
    penalty = triangle_contact_penalty(scene, lattice, el, surface_);
    tri_triangles_ = surface_.triangles.size();
    device_bytes_ += tri_triangles_ * (3 * 4 + 3 * 4) + (n_ + 1) * 4 +
                     3 * tri_triangles_ * scene.indenters.size() * 4 * real_size_;
  }
  contact_stiffness_n_m_ = penalty.stiffness_n_m;
  rest_offsets_ = scene.reference_state.active;
  hyper_ = el.hyperelastic;
  biphasic_ = el.biphasic;
  const PlanInputs plan_in = plan_inputs(scene, el.hyperelastic, el.biphasic, n_, el.held_count, tri_contact_, cl.info,
                                         cl.info.device.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>());
  plan_ = choose_launch_plan(plan_in, overrides);
  if (plan_.stress_pair) device_bytes_ += n_ * 4 * 4 * real_size_;  // the predicted stage's Q rows and C
  device_bytes_ += 2 * n_ * real_size_;  // the check's per-element scales
  require_fits_device(device_bytes_, n_, cells, el.hyperelastic, scene, cl.info);

  const PaddedGrid padded = make_padded_grid(lattice);
  const std::vector<cl_int>& grid = padded.element_of_cell;
  const std::vector<cl_uint>& cell_of = padded.cell_of_element;

  // The unloaded reference state: rest offsets (zero until set_rest_offsets), and for
  // hyperelastic tissue the rest frame R₀, J₀ (kernels/hyperelastic.cl); placeholders otherwise.
  const std::size_t offset_bytes = (rest_offsets_ ? n_ : 1) * 4 * real_size_;
  const std::size_t frame_bytes = (rest_offsets_ && hyper_ ? 3 * n_ : 1) * 4 * real_size_;
  if (rest_offsets_) device_bytes_ += offset_bytes + (hyper_ ? frame_bytes : 0);
  make_model_arena(el, grid, cell_of, offset_bytes);
  plan_.pred_packed = choose_pred_packing(plan_, plan_in, uniform_elements_, overrides);  // after the short loop's marks
  for (const IndenterSpec& ind : scene.indenters) motion_.push_back(starting_motion(ind));  // before the obstacle table
  path_segment_.assign(scene.indenters.size(), std::size_t(-1));
  // the volume constraint's surface elements, one work-item each (kernels/volume.cl: the volume
  // from Euler's theorem); the state arena sizes the partial sums by them
  std::vector<std::uint32_t> surface_index;
  const std::vector<cl_uint> surface_list =
      volume_ ? mesh_surface_elements(surface_, n_, surface_index) : std::vector<cl_uint>{};
  volume_surface_ = surface_list.size();
  volume_groups_ = (volume_surface_ + kCheckWorkGroup - 1) / kCheckWorkGroup;
  make_state_arena(state_bytes, frame_bytes);
  upload(el.displacement_m, std::vector<double>(3 * n_, 0.0));

  const std::size_t wg = kCheckWorkGroup;
  check_groups_ = (n_ + wg - 1) / wg;
  global_ = cl::NDRange(check_groups_ * wg);
  local_ = cl.info.is_gpu ? cl::NDRange(wg) : cl::NullRange;  // PoCL picks faster sizes itself
  for (const TorusSpec& t : scene.tori)
    for (const TorusKnot& k : t.schedule)
      require(k.minor_radius_m >= lattice.spacing_m,
              "torus '" + t.name + "' has a tube radius of " + std::to_string(k.minor_radius_m) +
                  " m, thinner than the lattice spacing " + std::to_string(lattice.spacing_m) + " m",
              "device.torus " + t.name + (t.line ? " (line " + std::to_string(t.line) + ")" : ""),
              "contact is tested at element centres, so a thinner tube could pass between them: make the minor "
              "radius at least one spacing, or refine the lattice");
  check_slots_ = kCheckBaseSlots + kCheckSlotsPerIndenter * int(scene.indenters.size()) +
                 kCheckSlotsPerTorus * int(scene.tori.size()) + (relax_ ? 4 : 0);
  const auto local_bytes = cl.info.device.getInfo<CL_DEVICE_LOCAL_MEM_SIZE>();
  require(std::size_t(check_slots_) * kCheckWorkGroup * real_size_ + kCheckWorkGroup * sizeof(cl_int) <= local_bytes,
          std::to_string(scene.indenters.size()) + " indenters and " + std::to_string(scene.tori.size()) +
              " tori need more local memory in the check kernel than '" + cl.info.name + "' has (" +
              std::to_string(local_bytes) + " bytes)",
          "indenter, device.torus", "use fewer indenters or tori, or float precision");
  partial_ = cl::Buffer(cl.context, CL_MEM_READ_WRITE, check_groups_ * check_slots_ * real_size_);
  partial_arg_ = cl::Buffer(cl.context, CL_MEM_READ_WRITE, check_groups_ * sizeof(cl_int));

  // Only the features this scene uses are compiled in.
  // Gravity is compiled in whenever the scene has a [gravity] section (set_gravity may change it).
  const bool gravity = scene.gravity.active;
  std::string options = "-cl-std=CL1.2 -cl-mad-enable";  // 2× on PoCL; a·b+c rounding only
  options += " -DVB_DOUBLE=" + std::to_string(precision_ == Precision::Double);
  options += " -DVB_GRAVITY=" + std::to_string(gravity);
  // Relaxation damps with its own adaptive rate (kernels/relax.cl); dashpots would only slow it.
  options += " -DVB_DASHPOT=" + std::to_string(!relax_ && scene.solver.dashpot_ratio > 0);
  options += " -DVB_GLOBAL_DAMPING=" + std::to_string(!relax_ && scene.solver.damping_per_s > 0);
  options += " -DVB_RELAX=" + std::to_string(relax_);
  options += " -DVB_INDENTERS=" + std::to_string(scene.indenters.size());
  options += " -DVB_CHECK_SLOTS=" + std::to_string(check_slots_);
  options += " -DVB_RSQRT=" + std::to_string(cl.info.is_gpu);
  options += " -DVB_CORRECT_REVERSE=" + std::to_string(plan_.correct_reverse) +
             " -DVB_REVERSE_BLOCK=" + std::to_string(std::max<std::size_t>(1, cl.info.simd_width)) + "u";
  // Denormal floats (< 1.2e-38: nothing in m, N, Pa) flushed to zero on GPUs: NVIDIA's rsqrt,
  // rcp and sqrt then skip their denormal fix-up: the 1.5M linear Heun float step 3-4.5% shorter
  // on the H200 (device time).
  // Not for the one-launch step, which it made 4% slower (36k linear), nor on CPUs, whose tests'
  // references keep IEEE denormals (docs/PERFORMANCE.md, "Denormals and the power cap").
  if (cl.info.is_gpu && !plan_.persistent.on) options += " -cl-denorms-are-zero";
  // Torus contact settles only with correctly rounded float division and square root: with
  // NVIDIA's default ones (about 2 ulp) a dome squeezed by an inflating torus kept a residual of
  // 6.6e-4 for 60,000 steps, against 1,600 steps to 6e-7 with this option, as on PoCL
  // (tests/engine/device/test_torus_contact.cpp; docs/PERFORMANCE.md, "GPU-only guards").
  const auto fp32 = cl.info.device.getInfo<CL_DEVICE_SINGLE_FP_CONFIG>();
  if (!scene.tori.empty() && (fp32 & CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT))
    options += " -cl-fp32-correctly-rounded-divide-sqrt";
  options += " -DVB_HYPER=" + std::to_string(el.hyperelastic);
  options += " -DVB_BIPHASIC=" + std::to_string(el.biphasic);
  options += " -DVB_CHECK_WG=" + std::to_string(kCheckWorkGroup);
  options += " -DVB_VOLUME=" + std::to_string(volume_);
  if (volume_) {
    const bool wide = cl.info.is_gpu &&
                      cl.info.device.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>() >= kVolumeGpuWorkGroup &&
                      kVolumeSlots * kVolumeGpuWorkGroup * real_size_ + 64 <= local_bytes;
    volume_wg_ = wide ? kVolumeGpuWorkGroup : std::size_t(kCheckWorkGroup);
    options += " -DVB_VOLUME_WG=" + std::to_string(volume_wg_);
  }
  options += " -DVB_STEP_LIST=" + std::to_string(plan_.step_list) + " -DVB_STEP_LIST_AT=" + std::to_string(step_list_at_) + "u";
  options += " -DVB_NV_PTX=" + std::to_string(nvidia_ptx(cl.info));
  options += plan_.build_options(volume_);
  {
    // One work-item per element (or listed element) in groups of the plan's size (0: the runtime
    // picks; the lanes kernels set their own range in make_lane_args).
    const std::size_t per = kSplitWorkGroup / std::size_t(plan_.force_split);
    const std::size_t wg = plan_.step_work_group;
    const std::size_t items = plan_.step_list ? std::max<std::size_t>(1, step_list_n_) : n_, rounding = wg ? wg : kStepWorkGroup;
    step_global_ = plan_.force_split > 1 ? cl::NDRange((n_ + per - 1) / per * kSplitWorkGroup)
                                    : cl::NDRange((items + rounding - 1) / rounding * rounding);
    step_local_ = plan_.force_split > 1 ? cl::NDRange(kSplitWorkGroup) : wg ? cl::NDRange(wg) : cl::NullRange;
  }
  const bool friction = std::any_of(scene.tori.begin(), scene.tori.end(), [](const TorusSpec& t) { return t.friction > 0; }) ||
                        std::any_of(scene.indenters.begin(), scene.indenters.end(),
                                    [](const IndenterSpec& i) { return i.friction > 0; });
  options += " -DVB_TORI=" + std::to_string(scene.tori.size());
  options += " -DVB_TORUS_BASE=" + std::to_string(torus_table_base());
  options += " -DVB_FRICTION=" + std::to_string(friction);
  options += " -DVB_REST_OFFSET=" + std::to_string(rest_offsets_);
  options += " -DVB_ARENA_UNIT=" + std::to_string(DeviceArena::kUnit);
  options += " -DVB_TRI_CONTACT=" + std::to_string(tri_contact_);
  // the penalty geometry in double where the device has it (kernels/triangle_contact.cl)
  options += " -DVB_TRI_FP64=" + std::to_string(tri_contact_ && cl_.info.fp64);
  const std::vector<std::string> sources = plan_.kernel_files(volume_, relax_);
  program_ = build_program(cl, sources, lattice_tables_source(), options);
  kernel_files_ = sources;
  build_options_ = options;
  if (hyper_) {
    // the stress of any u over every element (checks, host requests), and with plan_.stress_pair the
    // step's launch of both stages over the stress list (kernels/hyperelastic.cl: v, dt, where the
    // predicted stage's Q and C go, the list), all of whose arguments are set once
    const auto stress_kernel = [&](cl_uint list_n) {
      cl::Kernel k(program_, "element_stress");
      set_element_fit_args(k);
      k.setArg(0, at(u_));
      k.setArg(6, cl_uint(n_));
      k.setArg(7, at(rest_frame_));
      set_state_arena_arg(k);
      if (plan_.stress_pair) {
        k.setArg(8, at(v_));  // 9: dt (set_time_step_args)
        k.setArg(10, cl_uint2{{arena_at_pred_.s[5], arena_at_pred_.s[6]}});
        k.setArg(11, stress_list_at_);
        k.setArg(12, list_n);
      }
      return k;
    };
    stress_ = stress_kernel(0);
    if (plan_.stress_pair) step_stress_ = stress_kernel(cl_uint(stress_list_n_));
  }

  const bool heun = scene.solver.integrator == Integrator::Heun;
  if (heun) {
    predict_ = cl::Kernel(program_, plan_.lanes ? "heun_predict_lanes" : "heun_predict");
    correct_ = cl::Kernel(program_, plan_.lanes ? "heun_correct_lanes" : "heun_correct");
  } else if (relax_) {
    relax_kernel_ = cl::Kernel(program_, plan_.lanes ? "relax_step_lanes" : "relax_step");
    relax_scale_ = make_real_buffer(relaxation_mass_scale(el, dt_.row_stiffness_n_m, penalty.row_n_m));
    dt_.row_stiffness_n_m = {};  // the host copy is not needed again
    relax_kernel_.setArg(kStepIndenter + kIndenterArgs + 2, relax_scale_);
  } else {
    euler_ = cl::Kernel(program_, plan_.lanes ? "euler_step_lanes" : "euler_step");
  }
  check_ = cl::Kernel(program_, "check_state");
  for (cl::Kernel* k : {&euler_, &predict_, &correct_, &relax_kernel_}) {
    if (!(*k)()) continue;
    set_lattice_args(*k, kStepLattice);
    k->setArg(kStepIndenter, at(indenters_));
    set_indenter_times(*k, kStepIndenter, 0.0, 0.0);
    set_state_arena_arg(*k);  // then dt (set_time_step_args)
    k->setArg(kStepIndenter + kIndenterArgs + 1, cl_uint(plan_.step_list ? step_list_n_ : n_));  // VB_STEP_N
  }
  if (plan_.lanes) make_lane_args();
  if (heun) {
    set_step_state_args(predict_, u_, v_, u_tmp_, v_tmp_);
    set_step_state_args(correct_, u_, v_, u_tmp_, v_tmp_);  // reads the stage from u_tmp_, v_tmp_
    correct_.setArg(kStepLattice + 1, arena_at_pred_);  // the predicted stage's stress (arena_at_ without the pair)
  }
  set_lattice_args(check_, kCheckLattice);
  set_indenter_args(check_, kCheckIndenter, 0.0, 0.0);
  check_.setArg(kCheckIndenter + kIndenterArgs, partial_);
  check_.setArg(kCheckIndenter + kIndenterArgs + 1, partial_arg_);
  check_.setArg(kCheckIndenter + kIndenterArgs + 2, cl_uint(n_));
  check_scale_ = cl::Buffer(cl.context, CL_MEM_READ_ONLY, 2 * n_ * real_size_);
  write_check_scale(el);
  check_.setArg(kCheckIndenter + kIndenterArgs + 3, check_scale_);
  if (relax_) {
    const int relax_arg = kCheckVolume + (volume_ ? 2 : 0) + (scene.tori.empty() ? 0 : 1);
    check_.setArg(relax_arg, relax_scale_);
    // u and the lattice force at the previous check; zero = the rest state, where both are zero
    std::vector<char> zeros(2 * 4 * real_size_ * n_, 0);
    relax_prev_ = cl::Buffer(cl.context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, zeros.size(), zeros.data());
    relax_prev_valid_ = relax_from_rest_valid_;  // zero force at rest only while the held elements are there
    check_.setArg(relax_arg + 1, relax_prev_);
    set_real(relax_kernel_, kStepIndenter + kIndenterArgs + 3, damping_);
  }
  if (friction)  // check_state's friction_dt, just before VB_TRI_PARAMS (kernels/checks.cl)
    check_dt_arg_ = int(check_.getInfo<CL_KERNEL_NUM_ARGS>()) - 1 - (tri_contact_ ? kTriangleArgs : 0);
  if (volume_) make_volume_buffers(surface_, surface_list, surface_index);
  if (!scene.tori.empty()) make_contact_area_buffer();
  if (tri_contact_) make_triangle_contact_buffers();
  if (plan_.persistent.on) make_persistent_kernel();
  set_time_step_args();
  if (rest_offsets_) set_rest_offsets(std::vector<double>(3 * n_, 0.0));  // R₀ = I, J₀ = 1
}

void Simulator::set_time_step_args() {
  for (cl::Kernel* k : {&euler_, &predict_, &correct_, &relax_kernel_})
    if ((*k)()) set_real(*k, kStepIndenter + kIndenterArgs, dt_.dt_s);
  if (plan_.stress_pair) {  // element_stress's predicted stage (kernels/hyperelastic.cl)
    set_real(stress_, 9, dt_.dt_s);
    set_real(step_stress_, 9, dt_.dt_s);
  }
  if (check_dt_arg_ >= 0) set_real(check_, check_dt_arg_, dt_.dt_s);
  if (plan_.persistent.on) set_persistent_time_step();
}

void Simulator::make_lane_args() {
  // The lanes kernels step the free elements only (kernels/integrate_lanes.cl), in ascending order.
  // kLaneWidth elements per work-item: the list padded to a multiple of it with its last entry
  // (a placeholder 0 when nothing is free: OpenCL has no empty buffers)
  std::vector<cl_uint> free_list = free_elements(inverse_mass_);
  const std::size_t n_free = free_list.size(), items = (n_free + kLaneWidth - 1) / kLaneWidth;
  free_list.resize(std::max<std::size_t>(1, items) * kLaneWidth, free_list.empty() ? 0 : free_list.back());
  free_list_ = cl::Buffer(cl_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, free_list.size() * sizeof(cl_uint),
                          free_list.data());
  device_bytes_ += free_list.size() * sizeof(cl_uint);
  const std::size_t wg = kCheckWorkGroup;
  step_global_ = cl::NDRange(std::max<std::size_t>(1, (items + wg - 1) / wg) * wg);
  // after n: the free count, then the list; relaxation has its scale and damping between them
  for (cl::Kernel* k : {&euler_, &predict_, &correct_, &relax_kernel_}) {
    if (!(*k)()) continue;
    const int n_arg = kStepIndenter + kIndenterArgs + 1, extra = k == &relax_kernel_ ? 2 : 0;
    k->setArg(n_arg, cl_uint(n_free));
    k->setArg(n_arg + extra + 1, free_list_);
  }
  mirror_state();  // upload ran before the lanes were chosen
}

void Simulator::set_rest_offsets(const std::vector<double>& u0) {
  require(rest_offsets_, "rest offsets need a scene with a [reference_state] section", "reference_state");
  require(u0.size() == 3 * n_, "rest offsets do not match the model");
  if (precision_ == Precision::Double) write_xyz<double>(rest_offset_, u0, nullptr);
  else write_xyz<float>(rest_offset_, u0, nullptr);
  if (hyper_) {
    cl::Kernel k(program_, "rest_frame");
    k.setArg(0, rest_offset_);
    set_element_fit_args(k);
    k.setArg(6, rest_frame_);
    k.setArg(7, cl_uint(n_));
    enqueue(k);
  }
  if (relax_) {  // the Rayleigh quotients' previous state: the rest state, where the force is zero
    std::vector<double> prev(6 * n_, 0.0);
    for (std::size_t e = 0; e < n_; ++e)
      for (int c = 0; c < 3; ++c) prev[6 * e + c] = u0[3 * e + c];
    // 2n vectors (u0_e, 0): write_xyz takes them like any other list of vectors
    if (precision_ == Precision::Double) write_xyz<double>(relax_prev_, prev, nullptr);
    else write_xyz<float>(relax_prev_, prev, nullptr);
    held_u0_.clear();
    for (std::size_t e = 0; e < n_; ++e)
      if (inverse_mass_[e] == 0) held_u0_.insert(held_u0_.end(), {u0[3 * e], u0[3 * e + 1], u0[3 * e + 2]});
    update_relax_from_rest();
    relax_prev_valid_ = relax_from_rest_valid_;
  }
  if (volume_) {  // the constraint holds the unloaded state's volume
    std::vector<double> rest = element_positions_m(lattice_), unloaded = rest;
    for (std::size_t i = 0; i < unloaded.size(); ++i) unloaded[i] += u0[i];
    const double lattice_volume = double(surface_.complete_cell_count) * std::pow(lattice_.spacing_m, 3);
    rest_volume_m3_ = lattice_volume * vb::enclosed_volume_m3(surface_, unloaded) / vb::enclosed_volume_m3(surface_, rest);
    set_rest_volume_args();
  }
  cl_.queue.finish();
}

void Simulator::make_state_arena(std::size_t state_bytes, std::size_t frame_bytes) {
  // Everything the step's kernels read or write besides the model arena (kernels/common.cl,
  // VB_STATE_PARAM), zeros to start with but the obstacle table.
  const std::vector<unsigned char> table = real_bytes(obstacle_table());
  std::vector<std::pair<cl::Buffer*, std::size_t>> parts = {
      {&u_, state_bytes}, {&v_, state_bytes}, {&u_tmp_, state_bytes}, {&v_tmp_, state_bytes},
      {&rest_frame_, frame_bytes}, {&indenters_, table.size()}};
  if (volume_) {
    const std::size_t grad = 4 * real_size_ * n_, scalars = kVolumeScalars * real_size_;
    parts.insert(parts.end(),
                 {{&vol_grad_, grad}, {&vol_partial_, volume_groups_ * kVolumeSlots * real_size_}, {&vol_scalars_, scalars}});
    if (plan_.volume_launches == 0)  // the predicted stage's pending projection, and no projection
      parts.insert(parts.end(), {{&vol_grad_pred_, grad}, {&vol_scalars_pred_, scalars}, {&vol_no_scalars_, scalars}});
  }
  for (const auto& [buffer, bytes] : parts) state_.add(buffer == &indenters_ ? table.data() : nullptr, bytes);
  require_buffer_fits("the model's state", state_.bytes(), cl_.info);
  state_.create(cl_);
  for (std::size_t i = 0; i < parts.size(); ++i) *parts[i].first = state_.part(i);
}

void Simulator::make_model_arena(const ElementArrays& el, const std::vector<cl_int>& grid,
                                 const std::vector<cl_uint>& cell_of, std::size_t offset_bytes) {
  // One buffer for the arrays every stepping kernel reads (device_arena.hpp: each buffer argument
  // costs host time per launch on NVIDIA); slots in kernels/common.cl's order (VB_UNPACK_LATTICE).
  // Spring-only scenes get 1-element placeholders for the hyperelastic arrays; biphasic springs
  // need the tissue ids and the material table too (not Q and C).
  const bool per_tissue = hyper_ || el.biphasic;
  std::vector<cl_uchar> tissue(per_tissue ? n_ : 1, 0);
  if (per_tissue) std::copy(lattice_.tissue_of_element.begin(), lattice_.tissue_of_element.end(), tissue.begin());
  std::vector<double> table;
  for (const auto& row : el.material_table) table.insert(table.end(), row.begin(), row.end());
  if (!per_tissue) table.assign(12, 0.0);
  material_rows_ = per_tissue ? el.material_table.size() : 0;
  const std::vector<unsigned char> E = real_bytes(device_modulus(el.youngs_modulus_pa));
  const std::vector<unsigned char> materials = real_bytes(table);
  // kernels/hyperelastic.cl, hyper_store: Q's 3 rows (C = FᵀF's diagonal in w), C's other entries
  const std::size_t row_bytes = (hyper_ ? n_ : 1) * 4 * real_size_;
  const std::size_t slot[8] = {
      arena_.add(E.data(), E.size()),
      arena_.add(cell_of.data(), cell_of.size() * sizeof(cl_uint)),
      arena_.add(grid.data(), grid.size() * sizeof(cl_int)),
      arena_.add(tissue.data(), tissue.size()),
      arena_.add(materials.data(), materials.size()),
      arena_.add(nullptr, 3 * row_bytes),
      arena_.add(nullptr, row_bytes),
      arena_.add(nullptr, offset_bytes)};  // rest offsets: zero until set_rest_offsets
  // The predicted stage's Q and C (plan_.stress_pair): what heun_correct reads in place of slots 5 and 6.
  const std::size_t pred_q = plan_.stress_pair ? arena_.add(nullptr, 3 * row_bytes) : 0;
  const std::size_t pred_c = plan_.stress_pair ? arena_.add(nullptr, row_bytes) : 0;
  // The step's stress pass skips held elements that no free element reads (stress_list_n_).
  const std::vector<cl_uint> list = plan_.stress_pair ? elements_read_by_free(lattice_, inverse_mass_) : std::vector<cl_uint>{};
  stress_list_n_ = list.size() < n_ ? list.size() : 0;
  const std::size_t list_slot = stress_list_n_ ? arena_.add(list.data(), list.size() * sizeof(cl_uint)) : 0;
  device_bytes_ += stress_list_n_ * sizeof(cl_uint);
  const std::vector<cl_uint> step_list = plan_.step_list ? free_elements(inverse_mass_) : std::vector<cl_uint>{};
  step_list_n_ = step_list.size();
  const std::size_t step_list_slot = plan_.step_list ? arena_.add(step_list.data(), std::max<std::size_t>(1, step_list_n_) * sizeof(cl_uint)) : 0;
  device_bytes_ += step_list_n_ * sizeof(cl_uint);
  require_buffer_fits("the model's arrays", arena_.bytes(), cl_.info);
  arena_.create(cl_);
  for (int i = 0; i < 8; ++i) arena_at_.s[i] = arena_.offset_units(slot[i]);
  arena_at_pred_ = arena_at_;
  if (plan_.stress_pair) {
    arena_at_pred_.s[5] = arena_.offset_units(pred_q);
    arena_at_pred_.s[6] = arena_.offset_units(pred_c);
  }
  stress_list_at_ = stress_list_n_ ? arena_.offset_units(list_slot) : 0;
  step_list_at_ = plan_.step_list ? arena_.offset_units(step_list_slot) : 0;
  E_ = arena_.part(slot[0]);
  cell_ = arena_.part(slot[1]);
  materials_ = arena_.part(slot[4]);
  rest_offset_ = arena_.part(slot[7]);
}

std::vector<double> Simulator::device_modulus(const std::vector<double>& youngs_modulus_pa) {
  std::vector<double> marked =
      plan_.uniform_path ? mark_uniform_neighbourhoods(lattice_, youngs_modulus_pa, inverse_mass_, cl_.info.simd_width)
                    : youngs_modulus_pa;
  uniform_elements_ = std::size_t(std::count_if(marked.begin(), marked.end(), [](double E) { return E < 0; }));
  return marked;
}

std::vector<unsigned char> Simulator::real_bytes(const std::vector<double>& values) const {
  std::vector<unsigned char> out(values.size() * real_size_);
  if (precision_ == Precision::Double) {
    std::memcpy(out.data(), values.data(), out.size());
    return out;
  }
  for (std::size_t i = 0; i < values.size(); ++i) {  // "never" (1e300) saturates within float range
    const float f = float(std::clamp(values[i], -3e38, 3e38));
    std::memcpy(out.data() + i * sizeof f, &f, sizeof f);
  }
  return out;
}

void Simulator::write_check_scale(const ElementArrays& el) {
  // Each element's residual and speed over its own scales, E·h² and √(E/ρ), E the largest modulus
  // of the element and its free hyperelastic neighbours: their stress acts on it, so round-off in
  // a stiff neighbour's stress (float: ~1e-7 of it) must not hold a soft element above the test,
  // while one element further the soft tissue's own scale applies. A spring neighbour acts through
  // the connection's series stiffness, at most twice the element's own (docs/PHYSICS.md, section 9).
  // 1e300 (float: saturated) where E is not positive, so such an element never passes.
  const auto hyperelastic = [&](std::size_t e) {  // the kernels' law ids 1 and 2
    const double law = el.material_table.empty() ? 0 : el.material_table[lattice_.tissue_of_element[e]][0];
    return law == 1 || law == 2;
  };
  const double h = lattice_.spacing_m;
  std::vector<double> scale(2 * n_, 1e300);
  for (std::size_t e = 0; e < n_; ++e) {
    double E = el.youngs_modulus_pa[e];
    for (const std::int32_t j : lattice_.neighbours(e))
      if (j >= 0 && el.inverse_mass[std::size_t(j)] != 0 && hyperelastic(std::size_t(j)))
        E = std::max(E, el.youngs_modulus_pa[std::size_t(j)]);
    const double rho = el.mass_kg[e] / (h * h * h);
    if (!(E > 0) || !(rho > 0)) continue;
    scale[2 * e] = std::min(1e300, 1 / (E * h * h));
    scale[2 * e + 1] = std::min(1e300, std::sqrt(rho / E));
  }
  const std::vector<unsigned char> bytes = real_bytes(scale);
  cl_.queue.enqueueWriteBuffer(check_scale_, CL_TRUE, 0, bytes.size(), bytes.data());
}

cl::Buffer Simulator::make_real_buffer(const std::vector<double>& values) const {
  std::vector<unsigned char> data = real_bytes(values);
  return cl::Buffer(cl_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, data.size(), data.data());
}

namespace {
template <typename T, typename V4>
void set_vec(cl::Kernel& k, int index, const Vec3& v) {
  V4 x{};
  x.s[0] = T(v[0]); x.s[1] = T(v[1]); x.s[2] = T(v[2]); x.s[3] = T(0);
  k.setArg(index, x);
}
}  // namespace

void Simulator::set_real(cl::Kernel& k, int index, double x) const {
  if (precision_ == Precision::Double) k.setArg(index, x); else k.setArg(index, float(x));
}

void Simulator::set_world_vector(cl::Kernel& k, int index, const Vec3& world) const {
  const Vec3 x = lattice_.rotation.transpose() * world;  // kernels work in the lattice frame
  if (precision_ == Precision::Double) set_vec<double, cl_double4>(k, index, x);
  else set_vec<float, cl_float4>(k, index, x);
}

void Simulator::set_element_fit_args(cl::Kernel& k) {
  // kernels/hyperelastic.cl: element_stress and rest_frame take these after the displacements
  k.setArg(1, arena_.buffer());
  k.setArg(2, arena_at_);
  k.setArg(3, cl_int(stride_y_));
  k.setArg(4, cl_int(stride_z_));
  set_real(k, 5, lattice_.spacing_m);
}

void Simulator::set_lattice_args(cl::Kernel& k, int a) {
  k.setArg(a + 0, arena_.buffer());
  k.setArg(a + 1, arena_at_);
  k.setArg(a + 2, cl_int(stride_y_));
  k.setArg(a + 3, cl_int(stride_z_));
  set_real(k, a + 4, lattice_.spacing_m);
  set_real(k, a + 5, scene_.solver.dashpot_ratio);
  set_world_vector(k, a + kLatticeGravity, gravity_);
  set_real(k, a + 7, damping_);
  set_world_vector(k, a + 8, lattice_.origin_m);
  set_real(k, a + 9, scene_.solver.hourglass);
}

void Simulator::set_state_arena_arg(cl::Kernel& k) const {
  k.setArg(k.getInfo<CL_KERNEL_NUM_ARGS>() - 1, state_.buffer());
}

void Simulator::set_step_state_args(cl::Kernel& k, const cl::Buffer& u, const cl::Buffer& v, const cl::Buffer& u_out,
                                    const cl::Buffer& v_out) const {
  k.setArg(0, at(u));
  k.setArg(1, at(v));
  k.setArg(2, at(u_out));
  k.setArg(3, at(v_out));
}

void Simulator::launch(cl::Kernel& k, const cl::NDRange& global, const cl::NDRange& local) const {
  if (!cl_.profiling) {
    cl_.queue.enqueueNDRangeKernel(k, cl::NullRange, global, local);
    return;
  }
  cl::Event e;
  cl_.queue.enqueueNDRangeKernel(k, cl::NullRange, global, local, nullptr, &e);
  events_.emplace_back(k.getInfo<CL_KERNEL_FUNCTION_NAME>(), e);
}

std::map<std::string, KernelProfile> Simulator::kernel_profile() const {
  std::map<std::string, KernelProfile> out;
  cl_.queue.finish();
  for (const auto& [name, e] : events_) {
    const auto ns = e.getProfilingInfo<CL_PROFILING_COMMAND_END>() - e.getProfilingInfo<CL_PROFILING_COMMAND_START>();
    out[name].launches += 1;
    out[name].seconds += 1e-9 * double(ns);
  }
  return out;
}

void Simulator::enqueue(cl::Kernel& k) const { launch(k, global_, local_); }

void Simulator::enqueue_stress(const cl::Buffer& u, const cl::Buffer* pending_grad, const cl::Buffer* pending_scalars) {
  if (!hyper_) return;
  stress_.setArg(0, at(u));
  if (plan_.volume_launches == 0) {  // element_stress's pending projection (VB_VOLUME_FOLD)
    stress_.setArg(8, at(pending_grad ? *pending_grad : vol_grad_));
    stress_.setArg(9, at(pending_scalars ? *pending_scalars : vol_no_scalars_));
  }
  enqueue(stress_);
}

void Simulator::enqueue_stress_pair() {
  // Heun's two stages as two rows of work-items (kernels/hyperelastic.cl, element_stress), over
  // the stress list where it leaves elements out
  const std::size_t wg = kCheckWorkGroup, items = stress_list_n_ ? (stress_list_n_ + wg - 1) / wg * wg : global_[0];
  const cl::NDRange local = local_.dimensions() ? cl::NDRange(local_[0], 1) : cl::NullRange;
  launch(step_stress_, cl::NDRange(items, 2), local);
}

void Simulator::enqueue_check() const {
  // check_state declares reqd_work_group_size, so its local size is always given
  launch(check_, global_, cl::NDRange(kCheckWorkGroup));
}

void Simulator::advance(std::int64_t steps) {
  const bool indenter = !scene_.indenters.empty() || !scene_.tori.empty();  // obstacles that move in time
  const double dt = dt_.dt_s;
  const bool has_paths = std::any_of(scene_.indenters.begin(), scene_.indenters.end(),
                                     [](const IndenterSpec& ind) { return ind.path.size() >= 2; });
  events_.clear();
  for (std::int64_t s = 0; s < steps; ++s, ++steps_) {
    const double t0 = double(steps_) * dt, t1 = double(steps_ + 1) * dt;
    if (has_paths) follow_paths(t0);
    if (scene_.solver.integrator == Integrator::Heun) {
      const bool project = volume_ && (steps_ + 1) % scene_.volume.every == 0;
      if (plan_.persistent.on) {  // the whole step, its projections included
        enqueue_persistent_step(t0, t1, indenter, project);
        continue;
      }
      if (indenter) {
        set_indenter_times(predict_, kStepIndenter, t0, t1);
        set_indenter_times(correct_, kStepIndenter, t1, t1);
      }
      if (plan_.volume_launches == 0) {
        // Projections left pending (kernels/volume.cl, volume_pending): the readers of each
        // projected state apply it, and only the state's own gradient and scalars stay pending
        // after the step.
        set_fold_args(pending_, project);
        enqueue_stress(u_, &vol_grad_, pending_ ? &vol_scalars_ : &vol_no_scalars_);
        launch(predict_, step_global_, step_local_);
        if (project) enqueue_pending_projection(u_tmp_, v_tmp_, true);
        enqueue_stress(u_tmp_, &vol_grad_pred_, project ? &vol_scalars_pred_ : &vol_no_scalars_);
        launch(correct_, step_global_, step_local_);
        if (project) enqueue_pending_projection(u_, v_, false);
        pending_ = project;
        continue;
      }
      if (plan_.stress_pair) enqueue_stress_pair(); else enqueue_stress(u_);
      enqueue_triangle_contact(u_, t0);
      launch(predict_, step_global_, step_local_);
      // The predicted stage meets the constraint too, by the lagged pressure (in heun_predict) or
      // its own projection: its velocity along g would otherwise reach the corrector's dashpots
      // and leave a steady slip at the constrained equilibrium.
      if (project && !plan_.volume_lag) enqueue_volume_correction(u_tmp_, v_tmp_);
      if (!plan_.stress_pair) enqueue_stress(u_tmp_);
      enqueue_triangle_contact(u_tmp_, t1);
      launch(correct_, step_global_, step_local_);
    } else {
      cl::Kernel& k = relax_ ? relax_kernel_ : euler_;
      set_step_state_args(k, u_, v_, u_tmp_, v_tmp_);
      if (indenter) set_indenter_times(k, kStepIndenter, t0, t1);
      enqueue_stress(u_);
      enqueue_triangle_contact(u_, t0);
      launch(k, step_global_, step_local_);
      std::swap(u_, u_tmp_);
      std::swap(v_, v_tmp_);
    }
    if (volume_ && (steps_ + 1) % scene_.volume.every == 0) enqueue_volume_correction(u_, v_);
  }
  cl_.queue.flush();
}

StateCheck Simulator::check() {
  check_grid_barriers();
  apply_pending_projection();
  check_.setArg(0, u_);
  check_.setArg(1, v_);
  set_indenter_args(check_, kCheckIndenter, time_s(), time_s());
  enqueue_stress(u_);
  if (volume_) enqueue_volume_sums(true);  // the pressure the residual leaves out
  enqueue_triangle_contact(u_, time_s());
  enqueue_check();
  const std::vector<double> p = read_reals(partial_, check_groups_ * check_slots_);
  std::vector<cl_int> arg(check_groups_);
  cl_.queue.enqueueReadBuffer(partial_arg_, CL_TRUE, 0, arg.size() * sizeof(cl_int), arg.data());

  StateCheck c;
  c.indenter_force_n.assign(scene_.indenters.size(), Vec3::Zero());
  c.contact_elements.assign(scene_.indenters.size(), 0);
  c.tori.assign(scene_.tori.size(), TorusContactCheck{});
  for (std::size_t g = 0; g < check_groups_; ++g) {
    const double* q = &p[g * check_slots_];
    c.residual_ratio = std::max(c.residual_ratio, q[0]);
    c.speed_ratio = std::max(c.speed_ratio, q[5]);
    if (q[1] > c.max_speed_m_s || c.fastest_element < 0) {
      c.max_speed_m_s = q[1];
      c.fastest_element = arg[g];
    }
    c.kinetic_energy_j += q[2];
    c.max_displacement_m = std::max(c.max_displacement_m, q[3]);
    c.nonfinite_elements += std::llround(q[4]);
    for (std::size_t i = 0; i < scene_.indenters.size(); ++i) {
      const double* r = q + kCheckBaseSlots + kCheckSlotsPerIndenter * i;
      c.indenter_force_n[i] += lattice_.rotation * Vec3(r[0], r[1], r[2]);
      c.contact_elements[i] += std::llround(r[3]);
    }
    for (std::size_t i = 0; i < scene_.tori.size(); ++i) {
      const double* r = q + kCheckBaseSlots + kCheckSlotsPerIndenter * scene_.indenters.size() + kCheckSlotsPerTorus * i;
      TorusContactCheck& t = c.tori[i];
      t.force_n += lattice_.rotation * Vec3(r[0], r[1], r[2]);
      t.contact_elements += std::llround(r[3]);
      t.contact_area_m2 += r[4];
      t.normal_force_sum_n += r[5];
      t.peak_pressure_pa = std::max(t.peak_pressure_pa, r[6]);
      t.max_penetration_m = std::max(t.max_penetration_m, r[7]);
    }
  }
  if (volume_) c.enclosed_volume_m3 = read_enclosed_volume_m3();
  if (relax_) adapt_relaxation_damping(p);
  return c;
}

void Simulator::adapt_relaxation_damping(const std::vector<double>& partial) {
  // Underwood's adaptive dynamic relaxation: c = 2·ω_min damps the slowest mode critically. Every
  // Rayleigh quotient is ≥ ω_min², so the smallest one seen (of u, of the change since the last
  // check, and the previous estimate) is the best; it only moves down, towards ω_min². Capped
  // where symplectic Euler's damping factor 1 − c·dt would stop contracting.
  const int R = check_slots_ - 4;
  std::array<double, 4> sum{};
  for (std::size_t g = 0; g < check_groups_; ++g)
    for (int k = 0; k < 4; ++k) sum[k] += partial[g * check_slots_ + R + k];
  double omega_sq = relax_omega_sq_;
  for (int k : {0, 2}) {
    const bool valid = k == 0 ? relax_from_rest_valid_ : relax_prev_valid_;
    if (valid && sum[k] > 0 && sum[k + 1] > 0) omega_sq = std::min(omega_sq, sum[k] / sum[k + 1]);
  }
  relax_prev_valid_ = true;  // the check kernel stored this state for the next check
  if (!std::isfinite(omega_sq)) return;  // no displacement yet: keep c
  relax_omega_sq_ = omega_sq;
  damping_ = std::min(2 * std::sqrt(omega_sq), 0.5 / dt_.dt_s);
  set_real(relax_kernel_, kStepIndenter + kIndenterArgs + 3, damping_);
}

void Simulator::set_gravity(const Vec3& g) {
  require(scene_.gravity.active, "gravity can change only in a scene with a [gravity] section", "gravity");
  gravity_ = g;
  // the persistent step's lattice arguments start where the stepping kernels' do
  for (cl::Kernel* k : {&euler_, &predict_, &correct_, &relax_kernel_, &persistent_kernel_})
    if ((*k)()) set_world_vector(*k, kStepLattice + kLatticeGravity, g);
  set_world_vector(check_, kCheckLattice + kLatticeGravity, g);
  if (volume_) {
    set_world_vector(vol_partials_, 2 + kLatticeGravity, g);
    set_world_vector(vol_project_, 2 + kLatticeGravity, g);
    if (plan_.volume_launches == 0) set_world_vector(vol_pending_, 2 + kLatticeGravity, g);
  }
}

void Simulator::update_relax_from_rest() {
  relax_from_rest_valid_ = true;
  for (std::size_t i = 0; i < held_u_.size(); ++i)
    if (std::abs(held_u_[i] - (held_u0_.empty() ? 0.0 : held_u0_[i])) > 1e-9) relax_from_rest_valid_ = false;
}

}  // namespace vb
