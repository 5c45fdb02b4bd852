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

Simulator::Simulator(const Scene& scene, const Lattice& lattice, const ElementArrays& el, const ClContext& cl)
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
  plan_launches(scene, el, cl);
  if (stress_pair_) device_bytes_ += n_ * 4 * 4 * real_size_;  // the predicted stage's Q rows and C
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
  plan_pred_packing(scene, el, cl);  // after the short loop's marks
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
  options += " -DVB_UNIFORM_PATH=" + std::to_string(uniform_path_);
  options += " -DVB_PRED_PACKED=" + std::to_string(pred_packed_);
  options += " -DVB_CORRECT_REVERSE=" + std::to_string(correct_reverse_) +
             " -DVB_REVERSE_BLOCK=" + std::to_string(std::max<std::size_t>(1, cl.info.simd_width)) + "u";
  // Denormal floats (< 1.2e-38: nothing in m, N, Pa) flushed to zero on GPUs: NVIDIA's rsqrt,
  // rcp and sqrt then skip their denormal fix-up: the 1.5M linear Heun float step 3-4.5% shorter
  // on the H200 (device time).
  // Not for the one-launch step, which it made 4% slower (36k linear), nor on CPUs, whose tests'
  // references keep IEEE denormals (docs/PERFORMANCE.md, "Denormals and the power cap").
  if (cl.info.is_gpu && !persistent_.on) options += " -cl-denorms-are-zero";
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
    // The volume gradient's incident triangles as element pairs (two dependent loads per term
    // instead of four, kernels/volume.cl); VOXBREAST_VOLUME_PAIRS=0 keeps corner indices, to compare.
    const char* pairs = std::getenv("VOXBREAST_VOLUME_PAIRS");
    volume_pairs_ = !(pairs && std::atoi(pairs) == 0);
    options += " -DVB_VOLUME_PAIRS=" + std::to_string(volume_pairs_);
  }
  options += " -DVB_VOLUME_FOLD=" + std::to_string(volume_ && volume_launches_ == 0);
  options += " -DVB_SPLIT=" + std::to_string(force_split_);
  options += " -DVB_LANES=" + std::to_string(lanes_);
  options += " -DVB_STEP_LIST=" + std::to_string(step_list_) + " -DVB_STEP_LIST_AT=" + std::to_string(step_list_at_) + "u";
  options += " -DVB_NV_PTX=" + std::to_string(nvidia_ptx(cl.info));
  options += persistent_.options();
  options += " -DVB_VOLUME_LAG=" + std::to_string(volume_lag_);
  options += " -DVB_STRESS_PAIR=" + std::to_string(stress_pair_);
  {
    // One work-item per element (or listed element) in groups of default_step_work_group on GPUs
    // (step_work_group.hpp: 256 from 131,072 elements); PoCL picks its own unless
    // VOXBREAST_STEP_WG asks (not for the lanes kernels, make_lane_args: their own range).
    const std::size_t per = kSplitWorkGroup / std::size_t(force_split_);
    std::size_t wg = cl.info.is_gpu ? default_step_work_group(n_) : 0;
    if (const char* env = std::getenv("VOXBREAST_STEP_WG"); env && force_split_ == 1 && !lanes_)
      wg = step_work_group_override(env, cl.info.device.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>());
    const std::size_t items = step_list_ ? std::max<std::size_t>(1, step_list_n_) : n_, rounding = wg ? wg : kStepWorkGroup;
    step_global_ = force_split_ > 1 ? cl::NDRange((n_ + per - 1) / per * kSplitWorkGroup)
                                    : cl::NDRange((items + rounding - 1) / rounding * rounding);
    step_local_ = force_split_ > 1 ? cl::NDRange(kSplitWorkGroup) : wg ? cl::NDRange(wg) : cl::NullRange;
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
  // device_contact.cl first: the indenters' friction reuses its grip helpers.
  std::vector<std::string> sources = {"common.cl",         "hyperelastic.cl",     "device_contact.cl",
                                      "lattice_forces.cl", "triangle_contact.cl", "integrate.cl",
                                      "integrate_lanes.cl"};
  if (volume_) sources.push_back("volume.cl");
  sources.push_back("persistent.cl");
  if (relax_) sources.push_back("relax.cl");
  sources.push_back("checks.cl");
  program_ = build_program(cl, sources, lattice_tables_source(), options);
  kernel_files_ = sources;
  build_options_ = options;
  if (hyper_) {
    // the stress of any u over every element (checks, host requests), and with stress_pair_ the
    // step's launch of both stages over the stress list (kernels/hyperelastic.cl: v, dt, where the
    // predicted stage's Q and C go, the list), all of whose arguments are set once
    const auto stress_kernel = [&](cl_uint list_n) {
      cl::Kernel k(program_, "element_stress");
      set_element_fit_args(k);
      k.setArg(0, at(u_));
      k.setArg(6, cl_uint(n_));
      k.setArg(7, at(rest_frame_));
      set_state_arena_arg(k);
      if (stress_pair_) {
        k.setArg(8, at(v_));  // 9: dt (set_time_step_args)
        k.setArg(10, cl_uint2{{arena_at_pred_.s[5], arena_at_pred_.s[6]}});
        k.setArg(11, stress_list_at_);
        k.setArg(12, list_n);
      }
      return k;
    };
    stress_ = stress_kernel(0);
    if (stress_pair_) step_stress_ = stress_kernel(cl_uint(stress_list_n_));
  }

  const bool heun = scene.solver.integrator == Integrator::Heun;
  if (heun) {
    predict_ = cl::Kernel(program_, lanes_ ? "heun_predict_lanes" : "heun_predict");
    correct_ = cl::Kernel(program_, lanes_ ? "heun_correct_lanes" : "heun_correct");
  } else if (relax_) {
    relax_kernel_ = cl::Kernel(program_, lanes_ ? "relax_step_lanes" : "relax_step");
    relax_scale_ = make_real_buffer(relaxation_mass_scale(el, dt_.row_stiffness_n_m, penalty.row_n_m));
    dt_.row_stiffness_n_m = {};  // the host copy is not needed again
    relax_kernel_.setArg(kStepIndenter + kIndenterArgs + 2, relax_scale_);
  } else {
    euler_ = cl::Kernel(program_, lanes_ ? "euler_step_lanes" : "euler_step");
  }
  check_ = cl::Kernel(program_, "check_state");
  for (cl::Kernel* k : {&euler_, &predict_, &correct_, &relax_kernel_}) {
    if (!(*k)()) continue;
    set_lattice_args(*k, kStepLattice);
    k->setArg(kStepIndenter, at(indenters_));
    set_indenter_times(*k, kStepIndenter, 0.0, 0.0);
    set_state_arena_arg(*k);  // then dt (set_time_step_args)
    k->setArg(kStepIndenter + kIndenterArgs + 1, cl_uint(step_list_ ? step_list_n_ : n_));  // VB_STEP_N
  }
  if (lanes_) make_lane_args();
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
  if (persistent_.on) make_persistent_kernel();
  set_time_step_args();
  if (rest_offsets_) set_rest_offsets(std::vector<double>(3 * n_, 0.0));  // R₀ = I, J₀ = 1
}

void Simulator::set_time_step_args() {
  for (cl::Kernel* k : {&euler_, &predict_, &correct_, &relax_kernel_})
    if ((*k)()) set_real(*k, kStepIndenter + kIndenterArgs, dt_.dt_s);
  if (stress_pair_) {  // element_stress's predicted stage (kernels/hyperelastic.cl)
    set_real(stress_, 9, dt_.dt_s);
    set_real(step_stress_, 9, dt_.dt_s);
  }
  if (check_dt_arg_ >= 0) set_real(check_, check_dt_arg_, dt_.dt_s);
  if (persistent_.on) set_persistent_time_step();
}

// Heun's predicted stage packed (kernels/lattice_forces.cl, stage_load): ũ with ṽx in one real4,
// ṽy, ṽz in a real2, so a warp's read of a neighbour's stage touches 6 cache lines instead of 8
// (H200, linear cubes: heun_correct 10% shorter, the step 3-5% at 1.5M, 7% at 512k; docs/
// PERFORMANCE.md, "Packed predicted stage"). Where the short loop takes at least half the free elements: the general
// loop reads each neighbour's inverse mass from the state, a third line (the phantom at 50k-60k,
// none on the short loop: 0 to 5% slower). Only where heun_correct alone reads the stage: no volume
// constraint, indenters, tori or triangle contact, one work-item per element and no list (whose
// held elements' stage is a copy of the state). VOXBREAST_PRED_PACKED=0|1 overrides the device
// rule and the half, not the others.
void Simulator::plan_pred_packing(const Scene& scene, const ElementArrays& el, const ClContext& cl) {
  const bool allowed = scene.solver.integrator == Integrator::Heun && uniform_path_ && force_split_ == 1 &&
                       !persistent_.on && !step_list_ && !lanes_ && !volume_ && scene.indenters.empty() &&
                       scene.tori.empty() && !tri_contact_;
  pred_packed_ = allowed && default_pred_packing(cl.info.is_gpu, uniform_elements_, n_ - el.held_count);
  if (const char* env = std::getenv("VOXBREAST_PRED_PACKED")) pred_packed_ = allowed && std::atoi(env) != 0;
}

void Simulator::plan_launches(const Scene& scene, const ElementArrays& el, const ClContext& cl) {
  const bool heun_steps = scene.solver.integrator == Integrator::Heun;
  if (volume_) {
    // A projection is two launches on GPUs (volume_partials, volume_apply) and one elsewhere
    // (volume_project). On an H200 the one-launch form's last work-group, applying the projection
    // alone, took 21.8 µs against 7.9 + 10.8 µs for the two launches (docs/PERFORMANCE.md); on PoCL
    // the two cost the same. VOXBREAST_VOLUME_LAUNCHES=1|2 overrides, to compare them on a device.
    // 0 (Heun only): no apply launch at all, the kernels that read the state next apply the
    // pending projection (volume_pending; kernels/common.cl, VB_PENDING_PARAMS).
    volume_launches_ = cl.info.is_gpu ? 2 : 1;
    if (const char* env = std::getenv("VOXBREAST_VOLUME_LAUNCHES")) {
      const int k = std::atoi(env);
      if (k == 1 || k == 2) volume_launches_ = k;
      // Triangle contact reads the state without a pending projection: it keeps the apply launches.
      if (k == 0 && heun_steps && !tri_contact_) volume_launches_ = 0;
    }
  }
  const bool folded = volume_ && volume_launches_ == 0;
  // Heun's force passes on GPUs with each element's connections over 2 work-items for small
  // hyperelastic models (kernels/integrate.cl, VB_SPLIT): ~1,100 warps at 36k elements leave a
  // latency-bound pass short of threads. VOXBREAST_FORCE_SPLIT=1|2|4 overrides, on any device.
  force_split_ = heun_steps && cl.info.is_gpu && el.hyperelastic && n_ <= kSplitMaxElements ? 2 : 1;
  if (const char* env = std::getenv("VOXBREAST_FORCE_SPLIT")) {
    const int k = std::atoi(env);
    if (heun_steps && (k == 1 || k == 2 || k == 4)) force_split_ = k;
  }
  // Every integrator on CPUs for plain float spring models: the kernels that step 8 elements per
  // work-item in float8 vectors (kernels/integrate_lanes.cl, relax.cl); VOXBREAST_LANES=0 keeps the
  // real4 kernels, to compare.
  lanes_ = !cl.info.is_gpu && precision_ == Precision::Float && !el.hyperelastic && !el.biphasic &&
           scene.indenters.empty() && scene.tori.empty() && !tri_contact_ && !folded && !rest_offsets_ &&
           force_split_ == 1;
  if (const char* env = std::getenv("VOXBREAST_LANES")) lanes_ = lanes_ && std::atoi(env) != 0;
  // Heun's whole step in one launch where the device allows it (kernels/persistent.cl): not with
  // triangle contact (its own pass) or folded projections (another way to fewer launches).
  persistent_ = plan_persistent_step(cl.info, heun_steps && !tri_contact_ && !folded, el.hyperelastic, n_,
                                     force_split_, kPersistentMaxElements);
  // The stepping kernels over a list of the free elements (kernels/common.cl, VB_STEP_LIST), on
  // GPUs for large models with a quarter or more held (step_list_rule.hpp): those then cost no
  // work-item and no copy of their state per step (the phantom, two thirds held: Heun +10% at
  // 76k, +16% at 1.5M, up to +38% between; relaxation and Euler +2% to +41%). Not with the lanes
  // kernels (their own list), the split force pass or the one-launch step (their own layouts).
  // VOXBREAST_STEP_LIST=0|1 overrides the device rule, not the others.
  const bool list_allowed = !lanes_ && force_split_ == 1 && !persistent_.on;
  step_list_ = list_allowed && default_step_list(cl.info.is_gpu, n_, el.held_count, relax_ && el.hyperelastic);
  if (const char* env = std::getenv("VOXBREAST_STEP_LIST")) step_list_ = list_allowed && std::atoi(env) != 0;
  // Heun's corrector over the elements' blocks from the last to the first (kernels/integrate.cl,
  // VB_CORRECT_REVERSE; correct_order.hpp): it starts where the predictor ended (H200: linear
  // cubes of 1.0M and 1.5M elements 4-5% faster). One work-item per element in the elements'
  // order: not with the list, the split pass, the lanes kernels or the one-launch step.
  // VOXBREAST_CORRECT_REVERSE=0|1 overrides the device rule (size, volume), not the others.
  const bool reverse_allowed = heun_steps && !lanes_ && force_split_ == 1 && !persistent_.on && !step_list_;
  correct_reverse_ = reverse_allowed && default_correct_reverse(cl.info.is_gpu, n_, volume_);
  if (const char* env = std::getenv("VOXBREAST_CORRECT_REVERSE")) correct_reverse_ = reverse_allowed && std::atoi(env) != 0;
  // Linear springs on GPUs: elements whose neighbours share their E and mass take a short
  // connection loop (kernels/lattice_forces.cl, lattice_force_uniform; docs/PERFORMANCE.md),
  // marked by a negative E in whole warps (uniform_neighbourhood.hpp). Not in the one-launch step,
  // whose register cap the second loop overflows (36k cube 72.9k → 47.9k steps/s on the H200), nor
  // with the lanes kernels (skipping the neighbour's E saves little on a CPU). Off
  // by default with the step list (the H200 ran both together 11% slower than the short loop alone
  // on the 1.5M cube, and 4% slower than the list alone on the phantom). VOXBREAST_UNIFORM_PATH=0|1
  // overrides the device rule, not the others.
  const bool uniform_allowed = !el.hyperelastic && !el.biphasic && !rest_offsets_ && !lanes_ && !persistent_.on;
  uniform_path_ = uniform_allowed && cl.info.is_gpu && !step_list_;
  if (const char* env = std::getenv("VOXBREAST_UNIFORM_PATH")) uniform_path_ = uniform_allowed && std::atoi(env) != 0;
  // Heun's predicted stage under the last correction's pressure instead of a projection of its
  // own (docs/PHYSICS.md, "Volume preservation"): one launch fewer per step on CPUs, two on GPUs.
  // Projected as before when the scene asks, between corrections (every > 1: no multiplier to
  // lag), with folded projections, and in the one-launch step (kernels/persistent.cl keeps its
  // own schedule).
  // Relaxation's step feels the lagged pressure too (kernels/relax.cl: why).
  const bool lag_heun = heun_steps && scene.volume.predictor == VolumeSpec::Predictor::Pressure;
  volume_lag_ = volume_ && (lag_heun || relax_) && scene.volume.every == 1 && !folded && !persistent_.on;
  // Both of Heun's element stresses in one launch (kernels/hyperelastic.cl, VB_STRESS_PAIR): the
  // predicted stage moves each free element to ũ = u + dt·v whatever its force, so the stress at ũ
  // needs only (u, v). Not where something else moves ũ: indenters and tori project it out of
  // themselves, the predicted stage's own volume projection; nor with folded projections or the
  // one-launch step (their own passes). VOXBREAST_STRESS_PAIR=0 keeps two launches, to compare.
  stress_pair_ = hyper_ && heun_steps && scene.indenters.empty() && scene.tori.empty() && (!volume_ || volume_lag_) &&
                 !folded && !persistent_.on;
  if (const char* env = std::getenv("VOXBREAST_STRESS_PAIR")) stress_pair_ = stress_pair_ && std::atoi(env) != 0;
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
    if (volume_launches_ == 0)  // the predicted stage's pending projection, and no projection
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
  // The predicted stage's Q and C (stress_pair_): what heun_correct reads in place of slots 5 and 6.
  const std::size_t pred_q = stress_pair_ ? arena_.add(nullptr, 3 * row_bytes) : 0;
  const std::size_t pred_c = stress_pair_ ? arena_.add(nullptr, row_bytes) : 0;
  // The step's stress pass skips held elements that no free element reads (stress_list_n_).
  const std::vector<cl_uint> list = stress_pair_ ? elements_read_by_free(lattice_, inverse_mass_) : std::vector<cl_uint>{};
  stress_list_n_ = list.size() < n_ ? list.size() : 0;
  const std::size_t list_slot = stress_list_n_ ? arena_.add(list.data(), list.size() * sizeof(cl_uint)) : 0;
  device_bytes_ += stress_list_n_ * sizeof(cl_uint);
  const std::vector<cl_uint> step_list = step_list_ ? free_elements(inverse_mass_) : std::vector<cl_uint>{};
  step_list_n_ = step_list.size();
  const std::size_t step_list_slot = step_list_ ? arena_.add(step_list.data(), std::max<std::size_t>(1, step_list_n_) * sizeof(cl_uint)) : 0;
  device_bytes_ += step_list_n_ * sizeof(cl_uint);
  require_buffer_fits("the model's arrays", arena_.bytes(), cl_.info);
  arena_.create(cl_);
  for (int i = 0; i < 8; ++i) arena_at_.s[i] = arena_.offset_units(slot[i]);
  arena_at_pred_ = arena_at_;
  if (stress_pair_) {
    arena_at_pred_.s[5] = arena_.offset_units(pred_q);
    arena_at_pred_.s[6] = arena_.offset_units(pred_c);
  }
  stress_list_at_ = stress_list_n_ ? arena_.offset_units(list_slot) : 0;
  step_list_at_ = step_list_ ? arena_.offset_units(step_list_slot) : 0;
  E_ = arena_.part(slot[0]);
  cell_ = arena_.part(slot[1]);
  materials_ = arena_.part(slot[4]);
  rest_offset_ = arena_.part(slot[7]);
}

std::vector<double> Simulator::device_modulus(const std::vector<double>& youngs_modulus_pa) {
  std::vector<double> marked =
      uniform_path_ ? mark_uniform_neighbourhoods(lattice_, youngs_modulus_pa, inverse_mass_, cl_.info.simd_width)
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
  if (volume_launches_ == 0) {  // element_stress's pending projection (VB_VOLUME_FOLD)
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
      if (persistent_.on) {  // the whole step, its projections included
        enqueue_persistent_step(t0, t1, indenter, project);
        continue;
      }
      if (indenter) {
        set_indenter_times(predict_, kStepIndenter, t0, t1);
        set_indenter_times(correct_, kStepIndenter, t1, t1);
      }
      if (volume_launches_ == 0) {
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
      if (stress_pair_) enqueue_stress_pair(); else enqueue_stress(u_);
      enqueue_triangle_contact(u_, t0);
      launch(predict_, step_global_, step_local_);
      // The predicted stage meets the constraint too, by the lagged pressure (in heun_predict) or
      // its own projection: its velocity along g would otherwise reach the corrector's dashpots
      // and leave a steady slip at the constrained equilibrium.
      if (project && !volume_lag_) enqueue_volume_correction(u_tmp_, v_tmp_);
      if (!stress_pair_) enqueue_stress(u_tmp_);
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
    if (volume_launches_ == 0) set_world_vector(vol_pending_, 2 + kLatticeGravity, g);
  }
}

void Simulator::update_relax_from_rest() {
  relax_from_rest_valid_ = true;
  for (std::size_t i = 0; i < held_u_.size(); ++i)
    if (std::abs(held_u_[i] - (held_u0_.empty() ? 0.0 : held_u0_[i])) > 1e-9) relax_from_rest_valid_ = false;
}

}  // namespace vb
