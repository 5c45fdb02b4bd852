// Heun, symplectic Euler and dynamic relaxation (kernels/relax.cl) steps of spring models on CPUs
// (VB_LANES, docs/PERF_NOTES.md change 14): the same arithmetic as heun_predict, heun_correct,
// euler_step and relax_step on linear springs with gravity, global damping and dashpots, written
// on scalar components instead of real4.
// Why a second form: PoCL runs a work-group as a loop over its work-items and lets LLVM's loop
// vectoriser widen that loop, one work-item per SIMD lane; LLVM does not widen real4 values
// ("instruction return type cannot be vectorized"), so the real4 kernels run one element at a time.
// On scalars LLVM widens the loop 8 work-items wide (AVX-512 CPU, 256-bit vectors preferred: one
// vsqrtps per 8 square roots, the neighbours' loads gathered). Float only: in double LLVM's cost
// model declines the gathers, and the scalar form ran slower than the real4 one. Only scenes
// without indenters, tori, triangle contact, pending volume projections, rest offsets,
// hyperelastic or biphasic tissue use it (Simulator: lanes_); they are the plain lattice of most
// positioning and fitting runs.
#if VB_LANES

typedef struct {
  real x, y, z;
} lane3;

// The square root as LLVM's intrinsic (correctly rounded, as OpenCL's sqrt on PoCL): PoCL's library
// sqrt is a call it never inlines, and a call stops the vectoriser. OpenCL's sqrt for compilers
// that are not clang-based (no __builtin_sqrtf).
#if !defined(__clang__)
#define lane_sqrt sqrt
#elif VB_DOUBLE
#define lane_sqrt __builtin_sqrt
#else
#define lane_sqrt __builtin_sqrtf
#endif

// Element e's (x, y, z) from a real4 array read as reals: scalar loads, which LLVM gathers. `one` is
// 1, passed at run time (a kernel argument): with a constant 1 LLVM's SLP vectoriser, which PoCL
// runs before the work-item loop vectoriser, pairs the adjacent x and y loads into 2-wide vectors,
// and a vector-typed value in the loop stops the loop vectoriser (its remark: "instruction return
// type cannot be vectorized"); with `one` unknown the compiler cannot tell the loads are adjacent.
VB_INLINE lane3 lane_xyz(global const real* a, uint e, int one) {
  const lane3 r = {a[4 * e], a[4 * e + one], a[4 * e + 2 * one]};
  return r;
}

VB_INLINE real lane_w(global const real* a, uint e, int one) { return a[4 * e + 3 * one]; }

VB_INLINE void lane_store(global real* a, uint e, lane3 p, real w, int one) {
  a[4 * e] = p.x;
  a[4 * e + one] = p.y;
  a[4 * e + 2 * one] = p.z;
  a[4 * e + 3 * one] = w;
}

// Lattice force on element e (N): lattice_force_pending of kernels/lattice_forces.cl for linear
// springs (and dashpots under VB_DASHPOT), term by term in the same order. (Its short loop for
// uniform neighbourhoods, lattice_force_uniform, is not used with the lanes kernels: as a branch
// it stopped PoCL's vectoriser, 36k linear Heun 446 → 190 steps/s, and as a select it saves
// nothing on a CPU.)
VB_INLINE lane3 lane_lattice_force(uint e, lane3 ui, real wi, lane3 vi, global const real* u, global const real* v,
                                   global const real* E, global const uint* cell_of, global const int* grid, int sy,
                                   int sz, real h, real dashpot_ratio, int one) {
  const int cell = (int)cell_of[e];
  const real Ei = E[e];
  lane3 f = {0, 0, 0};
#pragma unroll
  for (int d = 0; d < 26; ++d) {
    // Branch-free, as in the real4 form: a missing neighbour reads the element itself, masked out.
    const int jn = grid[cell + VB_DIR[d][0] + sy * VB_DIR[d][1] + sz * VB_DIR[d][2]];
    const real present = jn >= 0 ? (real)1 : (real)0;
    const uint j = jn >= 0 ? (uint)jn : e;
    const lane3 uj = lane_xyz(u, j, one);
    const real rx = h * VB_DIR[d][0] + (uj.x - ui.x);
    const real ry = h * VB_DIR[d][1] + (uj.y - ui.y);
    const real rz = h * VB_DIR[d][2] + (uj.z - ui.z);
    const real len_sq = rx * rx + ry * ry + rz * rz;
    const real inv_len = len_sq > 0 ? 1 / lane_sqrt(len_sq) : (real)0;
    const real len = len_sq * inv_len;
    const real nx = rx * inv_len, ny = ry * inv_len, nz = rz * inv_len;
    const real Ej = E[j];
    const real rest = h * VB_DIR_LEN[d];
#if VB_DASHPOT
    const real w_sum = wi + lane_w(u, j, one);
    const real kE = present * VB_KAPPA[d] * h * (2 * Ei * Ej);
    const real q = 1 / ((Ei + Ej) * w_sum);
    const real k = kE * w_sum * q;
    real magnitude = k * (len - rest);
    const lane3 vj = lane_xyz(v, j, one);
    magnitude += 2 * dashpot_ratio * lane_sqrt(kE * q) * ((vj.x - vi.x) * nx + (vj.y - vi.y) * ny + (vj.z - vi.z) * nz);
#else
    const real k = present * VB_KAPPA[d] * h * (2 * Ei * Ej / (Ei + Ej));
    const real magnitude = k * (len - rest);
#endif
    f.x += magnitude * nx;
    f.y += magnitude * ny;
    f.z += magnitude * nz;
  }
  return f;
}

// Acceleration of a free element (w = 1/m ≠ 0) from its lattice force: acceleration_from of
// kernels/integrate.cl without indenters.
VB_INLINE lane3 lane_acceleration(lane3 f, real w, lane3 vi, real4 gravity, real damping) {
#if VB_GRAVITY
  f.x += gravity.x / w;
  f.y += gravity.y / w;
  f.z += gravity.z / w;
#endif
#if VB_GLOBAL_DAMPING
  f.x -= damping * vi.x / w;
  f.y -= damping * vi.y / w;
  f.z -= damping * vi.z / w;
#endif
  const lane3 a = {f.x * w, f.y * w, f.z * w};
  return a;
}

// The kernels step the free elements only, work-item k the element free_list[k] (n_free of them,
// ascending): held elements never move, so their entries in both state buffers stay as
// Simulator::upload wrote them. (A masked branch would not save their work: the vectorised loop
// computes every lane. On the phantom two thirds of the elements are the rigid chest wall.)

// One explicit stage of a free element (integrate.cl, explicit_stage): Heun's predictor
// ũ = u + dt·v, ṽ = v + dt·a(u, v), or a symplectic Euler step v' = v + dt·a(u, v), u' = u + dt·v'
// (`symplectic`, a constant at each call). With `relax` (a constant too; kernels/relax.cl:
// dynamic relaxation, symplectic) the acceleration is that of the fictitious dynamics,
// a·relax_scale − c·v, and v.w is 0 as relax_step stores it. (A branch the compiler cannot
// resolve, such as one on the pointer, would stop the vectoriser.)
VB_INLINE void lane_explicit_stage(global const real4* u4, global const real4* v4, global real4* u_out,
                                   global real4* v_out, VB_LATTICE_KERNEL_PARAMS, real dt, uint n_free, int one,
                                   global const uint* free_list, int symplectic, int relax,
                                   global const real* relax_scale, real c, VB_LAG_PARAMS) {
  VB_UNPACK_LATTICE;
  const uint k = get_global_id(0);
  if (k >= n_free) return;
  const uint e = free_list[k];
  global const real* u = (global const real*)u4;
  global const real* v = (global const real*)v4;
  const lane3 ui = lane_xyz(u, e, one), vi = lane_xyz(v, e, one);
  const real wi = lane_w(u, e, one), vw = lane_w(v, e, one);
  lane3 f = lane_lattice_force(e, ui, wi, vi, u, v, E, cell_of, grid, sy, sz, h, dashpot_ratio, one);
  if (lag) {  // under the lagged constraint pressure (Heun's predicted stage, relaxation): integrate.cl's less_lag
    const lane3 g = lane_xyz((global const real*)lag_g, e, one);
    f.x = fma(-lag_p, g.x, f.x);
    f.y = fma(-lag_p, g.y, f.y);
    f.z = fma(-lag_p, g.z, f.z);
  }
  lane3 a = lane_acceleration(f, wi, vi, gravity, damping);
  if (relax) {
    const real scale = relax_scale[e];
    const lane3 fictitious = {a.x * scale - c * vi.x, a.y * scale - c * vi.y, a.z * scale - c * vi.z};
    a = fictitious;
  }
  const lane3 vn = {vi.x + dt * a.x, vi.y + dt * a.y, vi.z + dt * a.z};
  const lane3 vm = symplectic ? vn : vi;  // the velocity the element moves with
  const lane3 un = {ui.x + dt * vm.x, ui.y + dt * vm.y, ui.z + dt * vm.z};
  lane_store((global real*)u_out, e, un, wi, one);
  lane_store((global real*)v_out, e, vn, relax ? 0 : vw, one);
}

// The entries take the state as offsets into the state arena, as integrate.cl's (no obstacles
// here: indenters_at is unused).
kernel void heun_predict_lanes(VB_STEP_STATE_PARAMS, VB_LATTICE_KERNEL_PARAMS, VB_INDENTER_AT_PARAMS, real dt,
                               uint n_free, int one, global const uint* free_list VB_LAG_KERNEL_PARAMS VB_STATE_PARAM) {
  lane_explicit_stage(VB_STEP_STATE_POINTERS, VB_LATTICE_KERNEL_ARGS, dt, n_free, one, free_list, 0, 0, 0, 0,
                      VB_LAG_KERNEL_ARGS);
}

kernel void euler_step_lanes(VB_STEP_STATE_PARAMS, VB_LATTICE_KERNEL_PARAMS, VB_INDENTER_AT_PARAMS, real dt,
                             uint n_free, int one, global const uint* free_list VB_STATE_PARAM) {
  lane_explicit_stage(VB_STEP_STATE_POINTERS, VB_LATTICE_KERNEL_ARGS, dt, n_free, one, free_list, 1, 0, 0, 0, VB_NO_LAG);
}

// Heun's corrector: u' = u + dt/2·(v + ṽ), v' = (v + ṽ)/2 + dt/2·a(ũ, ṽ), forces from the predicted
// stage.
kernel void heun_correct_lanes(VB_STEP_STATE_PARAMS, VB_LATTICE_KERNEL_PARAMS, VB_INDENTER_AT_PARAMS, real dt,
                               uint n_free, int one, global const uint* free_list VB_STATE_PARAM) {
  VB_UNPACK_LATTICE;
  const uint k = get_global_id(0);
  if (k >= n_free) return;
  const uint e = free_list[k];
  global real4* u4 = VB_STATE_AT(real4, u_at);
  global real4* v4 = VB_STATE_AT(real4, v_at);
  global const real* up_all = VB_STATE_AT(const real, u_out_at);  // the predicted stage
  global const real* vp_all = VB_STATE_AT(const real, v_out_at);
  global const real* u = (global const real*)u4;
  global const real* v = (global const real*)v4;
  const real wi = lane_w(u, e, one);
  const lane3 ui = lane_xyz(u, e, one), vi = lane_xyz(v, e, one);
  const lane3 up = lane_xyz(up_all, e, one), vp = lane_xyz(vp_all, e, one);
  const lane3 a = lane_acceleration(
      lane_lattice_force(e, up, wi, vp, up_all, vp_all, E, cell_of, grid, sy, sz, h, dashpot_ratio, one), wi, vp, gravity,
      damping);
  const real mean = (real)0.5, half_dt = (real)0.5 * dt;
  const lane3 vn = {(vi.x + vp.x) * mean + half_dt * a.x, (vi.y + vp.y) * mean + half_dt * a.y,
                    (vi.z + vp.z) * mean + half_dt * a.z};
  const lane3 un = {ui.x + half_dt * (vi.x + vp.x), ui.y + half_dt * (vi.y + vp.y), ui.z + half_dt * (vi.z + vp.z)};
  lane_store((global real*)u4, e, un, wi, one);
  lane_store((global real*)v4, e, vn, 0, one);
}

#endif
