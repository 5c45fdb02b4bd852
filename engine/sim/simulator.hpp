#pragma once
/// The OpenCL simulator: device buffers for one model, kernels built with only the features the
/// scene uses, and time stepping without host synchronisation between checks.
#include <CL/opencl.hpp>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/device_arena.hpp"
#include "engine/sim/element_setup.hpp"
#include "engine/sim/opencl_runtime.hpp"
#include "engine/sim/launch_plan.hpp"
#include "engine/sim/time_step.hpp"
#include "engine/surface/surface_mesh.hpp"

namespace vb {

/// Contact of one torus of the device at a check (kernels/checks.cl).
struct TorusContactCheck {
  Vec3 force_n = Vec3::Zero();        ///< force the tissue exerts on the torus (N, world frame)
  std::int64_t contact_elements = 0;  ///< free elements it pushes
  double contact_area_m2 = 0;         ///< their surface-area shares (engine/surface/surface_area.hpp)
  double normal_force_sum_n = 0;      ///< Σ |normal force| over its contact elements (N)
  double peak_pressure_pa = 0;        ///< largest normal force over area share of one element
  double max_penetration_m = 0;       ///< deepest free element inside the tube (m)
};

/// Where an indenter is: start + velocity·clamp(t − t0, 0, travel) (world frame). The scene's
/// constant-velocity press is one motion; a recorded trajectory is one per segment; a quasi-static
/// press places the indenter with zero velocity.
struct IndenterMotion {
  Vec3 start_m = Vec3::Zero();
  Vec3 velocity_m_s = Vec3::Zero();
  double t0_s = 0;
  double travel_time_s = 0;
  Vec3 position_m(double t_s) const {
    return start_m + velocity_m_s * std::clamp(t_s - t0_s, 0.0, travel_time_s);
  }
  /// From `from` at time t0 straight to `to`, reached at t1, then held (t1 ≤ t0: held at `to`).
  static IndenterMotion straight(const Vec3& from, const Vec3& to, double t0_s, double t1_s) {
    if (t1_s <= t0_s) return {to, Vec3::Zero(), 0, 0};
    return {from, (to - from) / (t1_s - t0_s), t0_s, t1_s - t0_s};
  }
};

/// Device-side reductions over the current state (see kernels/checks.cl).
struct StateCheck {
  /// largest net static force on a free element over its E·h², E the largest modulus of the
  /// element and its free hyperelastic neighbours (dimensionless)
  double residual_ratio = 0;
  double max_speed_m_s = 0;       ///< +inf when some value is not finite
  /// largest speed of a free element over its wave speed √(E/ρ), E as above (dimensionless)
  double speed_ratio = 0;
  double kinetic_energy_j = 0;
  double max_displacement_m = 0;
  std::vector<Vec3> indenter_force_n;           ///< per indenter: force the tissue exerts on it (N)
  std::vector<std::int64_t> contact_elements;   ///< per indenter: elements touching it
  std::vector<TorusContactCheck> tori;           ///< per torus of [[device.torus]]
  std::int64_t nonfinite_elements = 0;
  std::int64_t fastest_element = -1;  ///< element with the largest speed (or first non-finite)
  /// [volume] preserve only: volume enclosed by the surface (m³, world frame); else 0
  double enclosed_volume_m3 = 0;
};


/// Device time per kernel while profiling (ClContext with profiling on): launches and seconds.
struct KernelProfile {
  std::int64_t launches = 0;
  double seconds = 0;
};

class Simulator {
 public:
  /// Uploads the model. Throws vb::Error for double precision on a device without fp64, a model
  /// too large for the device's memory, or more indenters and tori than the check kernel's local
  /// memory holds.
  /// `overrides` force launch-plan choices where the plan allows them (launch_plan.hpp: to compare
  /// plans on a device, and to run another device's plan in tests); the physics is the same.
  Simulator(const Scene& scene, const Lattice& lattice, const ElementArrays& elements, const ClContext& cl,
            const PlanOverrides& overrides = {});

  /// The launch schedule this simulator took (launch_plan.hpp).
  const LaunchPlan& launch_plan() const { return plan_; }

  /// Enqueues `steps` time steps; returns without waiting for the device.
  void advance(std::int64_t steps);
  /// Runs the reduction kernel on the current state and waits for it. With the relaxation
  /// integrator it also sets the damping of the next steps to 2·√(Rayleigh quotient), critical
  /// for the lowest mode (docs/PHYSICS.md, "Fast equilibrium").
  StateCheck check();
  /// Changes gravity (world frame, m/s²) from the next step on: a posture change.
  void set_gravity(const Vec3& acceleration_m_s2);
  /// The unloaded reference state (scenes with [reference_state] only): element e rests at its
  /// voxel centre + u0[e] (n×3, m, world frame) instead of at its voxel centre; springs take
  /// their rest lengths and hyperelastic elements their rest shape from it (docs/PHYSICS.md §13).
  /// Displacements stay measured from the voxel centres (the CT). Zero until set.
  void set_rest_offsets(const std::vector<double>& u0_m);
  /// New moduli for the same model (a fit's next solve, engine/fit/forward_model.cpp): the moduli
  /// and material table of `elements`, which must be this model's arrays but for those (the same
  /// masses, held elements and laws). Recomputes dt and relaxation's mass scale and leaves the
  /// simulator as a new one built with `elements` starts: the state at their initial
  /// displacement and at rest, the clock at zero, gravity and indenter motions the scene's,
  /// relaxation's damping estimate forgotten; rest offsets (set_rest_offsets) stay. Costs the
  /// host's stability bounds and a few uploads, not the buffers, program and model a new
  /// simulator builds. Throws vb::Error for other masses, laws or sizes, and with triangle
  /// contact (its penalty follows the moduli).
  void set_materials(const ElementArrays& elements);
  /// Counts time from zero again (the next run starts at t = 0, indenters at their start).
  void restart_clock() { steps_ = 0; }

  /// Current state as n×3 doubles in the world frame.
  void download(std::vector<double>& u_m, std::vector<double>& v_m_s) const;
  void upload(const std::vector<double>& u_m, const std::vector<double>& v_m_s);
  /// Lattice spring + dashpot forces at the current state (n×3, N, world frame); for tests.
  std::vector<double> lattice_forces();
  /// [volume] preserve only: the device's enclosed volume (m³) and its gradient (n×3, m²; zero
  /// off the surface) at the current state, world frame; for tests.
  double enclosed_volume_m3();
  std::vector<double> volume_gradient_m2();
  /// volume of the surface at rest (m³, world frame); 0 without [volume] preserve
  double rest_volume_m3() const { return rest_volume_m3_; }
  /// [volume] preserve only: the surface mesh the constraint uses (else nullptr)
  const SurfaceMesh* surface_mesh() const { return volume_ ? &surface_ : nullptr; }

  double dt_s() const { return dt_.dt_s; }
  /// Relaxation: the smallest Rayleigh quotient seen, an upper bound on ω_min² of the fictitious
  /// dynamics (1/s²; infinite before the first displacement).
  double relaxation_omega_sq() const { return relax_omega_sq_; }
  bool relaxing() const { return relax_; }
  const TimeStepChoice& time_step() const { return dt_; }
  double time_s() const { return double(steps_) * dt_.dt_s; }
  std::int64_t steps() const { return steps_; }
  std::size_t device_bytes() const { return device_bytes_; }
  Precision precision() const { return precision_; }
  /// position of indenter i at simulated time t (m): its current motion (a recorded trajectory:
  /// the knots, interpolated)
  Vec3 indenter_position(std::size_t i, double t_s) const;
  /// Moves indenter i from the next step on (rewrites its row of the obstacle table).
  void set_indenter_motion(std::size_t i, const IndenterMotion& motion);
  /// Holds indenter i still at a world point (m) from the next step on: quasi-static probing.
  void place_indenter(std::size_t i, const Vec3& position_m) { set_indenter_motion(i, {position_m, Vec3::Zero(), 0, 0}); }
  /// [[device.torus]] only: each element's surface-area share (m², rest; 0 off the surface) that
  /// contact pressures divide by
  const std::vector<double>& contact_area_m2() const { return contact_area_host_; }
  const ClContext& context() const { return cl_; }
  /// the built program (its kernel names show which features were compiled in)
  const cl::Program& program() const { return program_; }
  /// kernel launches of the last advance() on a profiling queue (ClContext with profiling on),
  /// by kernel name; waits for the device
  std::map<std::string, KernelProfile> kernel_profile() const;
  /// Triangle contact (`contact_surface = "triangles"`) is compiled in and its buffers exist.
  bool triangle_contact() const { return tri_contact_; }
  /// per indenter its triangle-contact penalty stiffness (N/m; 0 for vertex contact)
  const std::vector<double>& contact_stiffness_n_m() const { return contact_stiffness_n_m_; }
  /// triangle contact only: the surface mesh it acts on
  const SurfaceMesh& contact_surface_mesh() const { return surface_; }
  /// Triangle contact only: the forces on the tissue at the current state, per indenter, triangle
  /// and corner (3 reals each, N, world frame; zero where it does not touch), as
  /// kernels/triangle_contact.cl computes them; for tests.
  std::vector<double> triangle_contact_forces_n();
  /// kernel launches per projection of the volume constraint: 1 (volume_project) or 2
  /// (volume_partials, volume_apply), or 0 (folded, Heun only): volume_pending computes the
  /// projection and the kernels that read the state next apply it, with no apply launch
  /// (kernels/volume.cl). The accessors below read the launch plan (launch_plan.hpp).
  int volume_launches() const { return plan_.volume_launches; }
  /// Whether Heun's predicted stage feels the lagged constraint pressure instead of being projected.
  bool volume_predictor_pressure() const { return plan_.volume_lag && !relax_; }
  /// Whether elements with a uniform neighbourhood take the short connection loop (linear springs),
  /// and how many do (engine/sim/uniform_neighbourhood.hpp).
  bool uniform_path() const { return plan_.uniform_path; }
  std::size_t uniform_elements() const { return uniform_elements_; }
  /// Whether Heun's predicted stage is stored packed (ũ, ṽx | ṽy, ṽz; kernels/lattice_forces.cl).
  bool pred_packed() const { return plan_.pred_packed; }
  /// Whether Heun's corrector steps the elements' blocks from the last to the first
  /// (engine/sim/correct_order.hpp).
  bool correct_reverse() const { return plan_.correct_reverse; }
  /// Whether the stepping kernels run over a list of the free elements (GPUs; kernels/integrate.cl).
  bool step_list() const { return plan_.step_list; }
  /// Work-items per group of the stepping kernels (step_work_group.hpp); 0: the device picks (PoCL).
  std::size_t step_work_group() const { return step_local_.dimensions() ? step_local_[0] : 0; }
  /// The volume constraint's scalars as the last kernel left them (kernels/volume.cl; lattice
  /// frame): the last correction's λ (m³ per unit w|g|²) and μ, the last sums' volume V (m³) and
  /// pressure p (Pa, computed by check()), and the lagged multiplier M (Pa·s: M/dt is the pressure
  /// the predicted stage feels; zero unless volume_predictor_pressure()).
  struct VolumeScalars {
    double lambda = 0, mu = 0, volume_m3 = 0, pressure_pa = 0, lagged = 0;
  };
  VolumeScalars volume_scalars() const;
  /// work-items per element in Heun's force passes (kernels/integrate.cl, VB_SPLIT): 2 on GPUs for
  /// hyperelastic models up to kSplitMaxElements, else 1
  int force_split() const { return plan_.force_split; }
  /// every integrator steps with the CPU kernels that take 8 free elements per work-item in float8
  /// vectors (kernels/integrate_lanes.cl): CPU devices, plain float spring models
  bool lanes() const { return plan_.lanes; }
  /// Heun's whole step runs as one launch (kernels/persistent.cl; NVIDIA GPUs, small models)
  bool persistent_step() const { return plan_.persistent.on; }
  /// Heun's two element stresses computed in one launch (kernels/hyperelastic.cl, VB_STRESS_PAIR)
  bool stress_pair() const { return plan_.stress_pair; }
  /// The elements whose stresses that launch computes: those some free element reads (a held
  /// element deep in the held region is left out), or every element.
  std::size_t stress_pass_elements() const { return stress_list_n_ ? stress_list_n_ : n_; }
  /// The kernel files and build options of this model's program (build_program), so that a test
  /// can build the variants a device here does not run (the one-launch step on PoCL).
  const std::vector<std::string>& kernel_files() const { return kernel_files_; }
  const std::string& build_options() const { return build_options_; }

 private:
  void set_indenter_args(cl::Kernel& k, int first_arg, double t_force, double t_project);
  /// where the scene starts an indenter: its constant-velocity press, or held at its path's first knot
  static IndenterMotion starting_motion(const IndenterSpec& indenter);
  /// the stage times alone (the table argument set once)
  void set_indenter_times(cl::Kernel& k, int first_arg, double t_force, double t_project);
  /// one indenter's row of the obstacle table (lattice frame, kernels/common.cl)
  std::vector<double> indenter_row(std::size_t i) const;
  /// recorded trajectories: switches each indenter's row to the segment holding time t
  void follow_paths(double t_s);
  void set_lattice_args(cl::Kernel& k, int first_arg);
  /// dt into every kernel that takes it (the stepping kernels, the paired stress pass, the check's
  /// friction, the one-launch step)
  void set_time_step_args();
  int check_dt_arg_ = -1;  ///< check_state's friction_dt (scenes with friction), else −1
  /// the modulus slot of the model arena as the kernels read it: E, uniform neighbourhoods marked
  std::vector<double> device_modulus(const std::vector<double>& youngs_modulus_pa);
  /// arguments 1–7 of the per-element gradient fits (tissue ids, materials, grid, spacing)
  void set_element_fit_args(cl::Kernel& k);
  void set_real(cl::Kernel& k, int index, double x) const;
  /// sets a world vector, rotated into the lattice frame the kernels work in
  void set_world_vector(cl::Kernel& k, int index, const Vec3& world) const;
  /// the first `count` reals of a buffer (float or double as the run's precision), blocking
  std::vector<double> read_reals(const cl::Buffer& buffer, std::size_t count) const;
  template <typename T>
  void read_xyz(const cl::Buffer& buffer, std::vector<double>& world) const;
  template <typename T>
  void write_xyz(const cl::Buffer& buffer, const std::vector<double>& world, const std::vector<double>* w) const;
  std::vector<double> to_lattice_frame(const std::vector<double>& world) const;
  void enqueue(cl::Kernel& k) const;
  void enqueue_check() const;
  void adapt_relaxation_damping(const std::vector<double>& partial);
  /// element stress of u; with folded projections (plan_.volume_launches == 0), with u's pending projection (gradient,
  /// scalars; none when null)
  void enqueue_stress(const cl::Buffer& u, const cl::Buffer* pending_grad = nullptr,
                      const cl::Buffer* pending_scalars = nullptr);
  /// element stresses of (u_, v_) and of Heun's predicted stage u_ + dt·v_ in one launch (plan_.stress_pair)
  void enqueue_stress_pair();
  void make_model_arena(const ElementArrays& el, const std::vector<cl_int>& grid, const std::vector<cl_uint>& cell_of,
                        std::size_t offset_bytes);
  std::vector<unsigned char> real_bytes(const std::vector<double>& values) const;  ///< in the model's precision
  /// The rigid-obstacle table the kernels read (lattice frame): indenter rows (a placeholder row if
  /// none), then torus rows and their inflation knots (kernels/device_contact.cl).
  std::vector<double> obstacle_table() const;
  /// torus rows start here in the table (reals)
  std::size_t torus_table_base() const;
  void make_contact_area_buffer();
  /// read-only buffer of reals in the run's precision
  cl::Buffer make_real_buffer(const std::vector<double>& values) const;

  const Scene& scene_;
  const Lattice& lattice_;
  const ClContext& cl_;
  LaunchPlan plan_;  ///< chosen once in the constructor (choose_launch_plan)
  Precision precision_;
  std::size_t n_;
  TimeStepChoice dt_;
  std::int64_t steps_ = 0;
  std::size_t device_bytes_ = 0;
  std::size_t real_size_;
  std::vector<double> inverse_mass_;
  int stride_y_ = 0, stride_z_ = 0;
  cl::NDRange global_, local_;
  std::size_t check_groups_ = 0;

  /// u_, v_, u_tmp_, v_tmp_, rest_frame_, indenters_ and the volume constraint's buffers are
  /// sub-buffers of one arena (kernels/common.cl, VB_STATE_PARAM): the step's kernels take the
  /// arena and offsets, every other use the sub-buffers.
  DeviceArena state_;
  void make_state_arena(std::size_t state_bytes, std::size_t frame_bytes);
  /// the state arena offset of one of its sub-buffers (what the step's kernels take)
  cl_uint at(const cl::Buffer& part) const { return state_.offset_units_of(part); }
  /// the state arena as a step kernel's last argument
  void set_state_arena_arg(cl::Kernel& k) const;
  /// the stepping kernels' first four arguments: where they read u, v and write the stage
  void set_step_state_args(cl::Kernel& k, const cl::Buffer& u, const cl::Buffer& v, const cl::Buffer& u_out,
                           const cl::Buffer& v_out) const;
  cl::Buffer u_, v_, u_tmp_, v_tmp_, partial_, partial_arg_;
  /// E, cell_of, grid, tissue ids, material table, Q, C, rest offsets (kernels/common.cl,
  /// VB_UNPACK_LATTICE) and their offsets; E_, cell_, materials_, rest_offset_ are the host's views of four.
  DeviceArena arena_;
  cl_uint8 arena_at_{};
  cl_uint8 arena_at_pred_{};  ///< arena_at_ with the predicted stage's Q and C (plan_.stress_pair), for heun_correct
  /// plan_.stress_pair: the elements the step's stress pass covers (elements_read_by_free, in the arena
  /// at stress_list_at_), 0 when that is every element
  std::size_t stress_list_n_ = 0;
  cl_uint stress_list_at_ = 0;
  cl::Buffer E_, cell_, materials_;
  bool hyper_ = false;
  bool biphasic_ = false;  ///< biphasic springs compiled in (VB_BIPHASIC)
  std::size_t material_rows_ = 0;  ///< material table rows in the arena (0: a placeholder, springs only)
  cl::Buffer indenters_;  ///< rigid-obstacle table: indenters and tori (lattice frame)
  std::vector<IndenterMotion> motion_;  ///< per indenter, what its row holds now
  std::vector<std::size_t> path_segment_;  ///< per indenter with a trajectory: the segment its row holds
  cl::Buffer contact_area_;  ///< [[device.torus]]: per element surface-area share (m²)
  std::vector<double> contact_area_host_;
  int check_slots_ = 0;  ///< hyperelastic: tissue ids, law table, Q and F rows
  cl::Kernel stress_;
  cl::Kernel step_stress_;  ///< plan_.stress_pair: element_stress with the step's arguments (enqueue_stress_pair)
  cl::Program program_;
  std::vector<std::string> kernel_files_;
  std::string build_options_;
  cl::Kernel euler_, predict_, correct_, relax_kernel_;
  bool relax_ = false;
  double damping_ = 0;  ///< global damping (1/s); adapted at each check when relaxing
  double relax_omega_sq_ = INFINITY;  ///< relaxation: smallest Rayleigh quotient so far (1/s²)
  // A Rayleigh quotient bounds ω_min² only for a displacement that vanishes on the held elements:
  // u from rest while they sit at rest (not under a posed anchor, whose rigid turn has no energy),
  // and the change since the previous check of the same run (not across an upload).
  bool relax_from_rest_valid_ = true;
  bool relax_prev_valid_ = false;
  std::vector<double> held_u_, held_u0_;  ///< relaxation: the held elements' u and rest offset (m)
  void update_relax_from_rest();
  Vec3 gravity_ = Vec3::Zero();
  cl::Buffer relax_scale_, relax_prev_;
  cl::Buffer check_scale_;  ///< per element 1/(E·h²), 1/√(E/ρ) (kernels/checks.cl)
  void write_check_scale(const ElementArrays& el);
  bool rest_offsets_ = false;
  cl::Buffer rest_offset_, rest_frame_;  ///< u0 per element; R₀ rows and J₀ (hyperelastic)
  mutable cl::Kernel check_;
  /// enqueues k (records its event on a profiling queue)
  void launch(cl::Kernel& k, const cl::NDRange& global, const cl::NDRange& local) const;
  mutable std::vector<std::pair<std::string, cl::Event>> events_;  ///< profiling queues only

  // Volume constraint ([volume] preserve): the surface mesh, uploaded once.
  /// surface, surface_index: the mesh's surface elements and each element's place among them
  void make_volume_buffers(const SurfaceMesh& mesh, const std::vector<cl_uint>& surface,
                           const std::vector<std::uint32_t>& surface_index);
  /// enqueues the partial sums (with the residual pressure when with_force) and λ, μ, V, p
  void enqueue_volume_sums(bool with_force);
  void enqueue_volume_sums(bool with_force, const cl::Buffer& u, const cl::Buffer& v);
  void enqueue_volume_partials(bool with_force, const cl::Buffer& u, const cl::Buffer& v);
  /// projects the state (u, v) onto V = V0 and removes its velocity along g
  void enqueue_volume_correction(const cl::Buffer& u, const cl::Buffer& v);
  /// V (m³, world frame) from the last volume_finish
  double read_enclosed_volume_m3() const;
  /// the rest volume (lattice frame) into the kernels that compute λ
  void set_rest_volume_args();
  // folded projections (plan_.volume_launches == 0): projections left pending
  /// the stepping kernels' pending projections: of (u, v) and of the predicted stage
  void set_fold_args(bool state_pending, bool pred_pending);
  /// volume_pending on (u, v): the gradient and scalars of the state's or the predicted stage's
  void enqueue_pending_projection(const cl::Buffer& u, const cl::Buffer& v, bool predicted);
  /// applies the state's pending projection (volume_apply) before anything else reads u, v
  void apply_pending_projection() const;
  mutable bool pending_ = false;  ///< (u_, v_) has a projection pending (vol_grad_, vol_scalars_)
  /// the lanes kernels' arguments: the free elements' list (free_list_, padded to kLaneWidth), their count
  void make_lane_args();
  /// copies (u, v) into the scratch pair (u_tmp_, v_tmp_): the lanes kernels and the listed step
  /// (plan_.step_list) never write held elements, so both pairs must hold them (upload, make_lane_args)
  void mirror_state();
  std::size_t step_list_n_ = 0;      ///< free elements in it
  cl_uint step_list_at_ = 0;         ///< its offset in the model arena (units; compiled in)
  cl::Buffer free_list_;
  /// the stepping kernels (Heun's VB_SPLIT; lanes and the step list: the free elements)
  cl::NDRange step_global_, step_local_;
  cl::Buffer vol_grad_pred_, vol_scalars_pred_, vol_no_scalars_;
  cl::Kernel vol_pending_;
  bool volume_ = false;
  SurfaceMesh surface_;
  double rest_volume_m3_ = 0, frame_sign_ = 1;  ///< det(rotation): lattice-frame V = sign·V_world
  std::size_t volume_surface_ = 0, volume_groups_ = 0;
  std::size_t volume_wg_ = 0;   ///< work-group size of volume_project (VB_VOLUME_WG)
  std::size_t uniform_elements_ = 0;  ///< elements marked
  DeviceArena vol_mesh_;  ///< triangles, surface elements, incident start, incident (kernels/volume.cl)
  cl_uint4 vol_mesh_at_{};
  cl::Buffer vol_grad_, vol_partial_,
      vol_scalars_, vol_done_;
  cl::Kernel vol_partials_, vol_finish_, vol_project_;
  mutable cl::Kernel vol_apply_;

  // The persistent Heun step (kernels/persistent.cl, simulator_persistent.cpp).
  void make_persistent_kernel();
  void enqueue_persistent_step(double t0_s, double t1_s, bool moving_obstacles, bool project);
  /// V0 (lattice frame) into the persistent kernel (set_rest_volume_args calls it)
  void set_persistent_rest_volume(double v0);
  void set_persistent_time_step();
  /// throws vb::Error when a grid barrier timed out (work-groups not all resident); check() and
  /// download() call it
  void check_grid_barriers() const;
  cl::Kernel persistent_kernel_;
  cl::Buffer grid_sync_;       ///< barrier count, fault flag
  cl_uint sync_start_ = 0;     ///< the count when the next launch starts
  Vec3 vol_centre_ = Vec3::Zero();

  // Triangle contact (kernels/triangle_contact.cl): the surface mesh (surface_), uploaded once.
  void make_triangle_contact_buffers();
  /// per-triangle corner forces for the state u at time t (nothing without triangle contact)
  void enqueue_triangle_contact(const cl::Buffer& u, double t_s);
  bool tri_contact_ = false;
  std::size_t tri_triangles_ = 0;
  std::vector<double> contact_stiffness_n_m_;
  cl::Buffer tri_elements_, tri_start_, tri_corner_, corner_force_;
  cl::Kernel tri_kernel_;
};

}  // namespace vb
