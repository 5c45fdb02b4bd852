// Heun, symplectic Euler and dynamic relaxation (kernels/relax.cl) steps of spring models on CPUs
// (VB_LANES, docs/PERFORMANCE.md, "CPU lanes kernels as float8"): the same arithmetic as heun_predict,
// heun_correct, euler_step and relax_step on linear springs with gravity, global damping and
// dashpots, each work-item stepping VB_LANE_WIDTH free elements at once in float8 vectors.
// Why a second form: PoCL runs a work-group as a loop over its work-items, and the real4 kernels
// step one element per iteration on scalar SSE instructions. A form on scalar components
// that left the widening across work-items to LLVM's loop vectoriser; its cost model
// accepted the neighbours' gathers on AVX-512 CPUs only, so on AVX2 CPUs (AMD EPYC Zen 3, PoCL's
// "haswell") the loop ran scalar again, with no sign but the speed. Here the vectors are written
// out: every CPU with 256-bit vectors runs 8 elements per instruction, whatever a cost model says.
// Float only (Simulator: lanes_). Only scenes without indenters, tori, triangle contact, pending
// volume projections, rest offsets, hyperelastic or biphasic tissue use it; they are the plain
// lattice of most positioning and fitting runs.
#if VB_LANES
#if VB_DOUBLE
#error "the lanes kernels are float only (Simulator::lanes_)"
#endif

// Elements per work-item: one 256-bit vector of floats (engine/sim/kernel_arg_layout.hpp has the
// host's copy, kLaneWidth, which pads the free list to a multiple of it).
#define VB_LANE_WIDTH 8

typedef struct {
  float8 x, y, z;
} lanes3;

// a[j.s0] … a[j.s7]: eight scalar loads.
VB_INLINE float8 gather(global const float* a, uint8 j) {
  return (float8)(a[j.s0], a[j.s1], a[j.s2], a[j.s3], a[j.s4], a[j.s5], a[j.s6], a[j.s7]);
}

VB_INLINE int8 gather_int(global const int* a, int8 j) {
  return (int8)(a[j.s0], a[j.s1], a[j.s2], a[j.s3], a[j.s4], a[j.s5], a[j.s6], a[j.s7]);
}

// The components of eight float4 as four float8: r0 … r3 hold elements (0, 4), (1, 5), (2, 6),
// (3, 7), one per 128-bit half; a 4 × 8 transpose in shuffles.
VB_INLINE void transpose4(float8 r0, float8 r1, float8 r2, float8 r3, float8* x, float8* y, float8* z, float8* w) {
  // per half: (x0 x1 y0 y1), (z0 z1 w0 w1) of elements 0, 1 (4, 5) and of 2, 3 (6, 7)
  const float8 xy01 = (float8)(r0.s0, r1.s0, r0.s1, r1.s1, r0.s4, r1.s4, r0.s5, r1.s5);
  const float8 zw01 = (float8)(r0.s2, r1.s2, r0.s3, r1.s3, r0.s6, r1.s6, r0.s7, r1.s7);
  const float8 xy23 = (float8)(r2.s0, r3.s0, r2.s1, r3.s1, r2.s4, r3.s4, r2.s5, r3.s5);
  const float8 zw23 = (float8)(r2.s2, r3.s2, r2.s3, r3.s3, r2.s6, r3.s6, r2.s7, r3.s7);
  *x = (float8)(xy01.s01, xy23.s01, xy01.s45, xy23.s45);
  *y = (float8)(xy01.s23, xy23.s23, xy01.s67, xy23.s67);
  *z = (float8)(zw01.s01, zw23.s01, zw01.s45, zw23.s45);
  *w = (float8)(zw01.s23, zw23.s23, zw01.s67, zw23.s67);
}

// The components of the eight float4 a[j.s0] … a[j.s7]: eight 16-byte loads (a gather per
// component would take four times the loads).
VB_INLINE void gather4(global const float4* a, uint8 j, float8* x, float8* y, float8* z, float8* w) {
  transpose4((float8)(a[j.s0], a[j.s4]), (float8)(a[j.s1], a[j.s5]), (float8)(a[j.s2], a[j.s6]),
             (float8)(a[j.s3], a[j.s7]), x, y, z, w);
}

// The same for a run a[j0] … a[j0 + 7]: addresses from one index, no lane taken apart.
VB_INLINE void load4_run(global const float4* a, uint j0, float8* x, float8* y, float8* z, float8* w) {
  a += j0;
  transpose4((float8)(a[0], a[4]), (float8)(a[1], a[5]), (float8)(a[2], a[6]), (float8)(a[3], a[7]), x, y, z, w);
}

// a[e.sl] = (x.sl, y.sl, z.sl, w.sl) for the first `count` lanes (count ≥ 1). transpose4 is its
// own inverse: on (x, y, z, w) it gives elements (0, 4), (1, 5), (2, 6), (3, 7) as float4 halves.
VB_INLINE void scatter4(global float4* a, uint8 e, uint count, float8 x, float8 y, float8 z, float8 w) {
  float8 r04, r15, r26, r37;
  transpose4(x, y, z, w, &r04, &r15, &r26, &r37);
  a[e.s0] = r04.lo;
  if (count > 1) a[e.s1] = r15.lo;
  if (count > 2) a[e.s2] = r26.lo;
  if (count > 3) a[e.s3] = r37.lo;
  if (count > 4) a[e.s4] = r04.hi;
  if (count > 5) a[e.s5] = r15.hi;
  if (count > 6) a[e.s6] = r26.hi;
  if (count > 7) a[e.s7] = r37.hi;
}

// (0, 1, …, 7): a run of indices is its first plus this.
#define VB_LANE_IOTA ((int8)(0, 1, 2, 3, 4, 5, 6, 7))

// Lattice force on elements e (N): lattice_force_pending of kernels/lattice_forces.cl for linear
// springs (and dashpots under VB_DASHPOT), term by term in the same order, so each lane rounds as
// the real4 kernel does. Where the 8 elements are a run of cells along x (`run`), so is each of
// their neighbourhoods' 26 directions, and a direction whose 8 neighbours are all there, numbered
// in a run, is read with plain vector loads; any other is gathered lane by lane. (The real4
// form's short loop for uniform neighbourhoods, lattice_force_uniform, is not used here: a CPU
// gains little from skipping the neighbour's E.)
VB_INLINE lanes3 lanes_lattice_force(uint8 e, lanes3 ui, float8 wi, lanes3 vi, global const float4* u,
                                     global const float4* v, global const float* E, global const uint* cell_of,
                                     global const int* grid, int sy, int sz, float h, float dashpot_ratio) {
  const int8 cell = gather_int((global const int*)cell_of, as_int8(e));
  const int run = all(cell == cell.s0 + VB_LANE_IOTA);
  const float8 Ei = gather(E, e);
  lanes3 f = {(float8)0, (float8)0, (float8)0};
#pragma unroll 2
  for (int d = 0; d < 26; ++d) {
    const int offset = VB_DIR[d][0] + sy * VB_DIR[d][1] + sz * VB_DIR[d][2];
    float8 ujx, ujy, ujz, wj, Ej;
    uint8 j;
    int8 jn = run ? vload8(0, grid + cell.s0 + offset) : (int8)(-1);
    const int dense = run && jn.s0 >= 0 && all(jn == jn.s0 + VB_LANE_IOTA);
    if (dense) {
      load4_run(u, jn.s0, &ujx, &ujy, &ujz, &wj);
      Ej = vload8(0, E + jn.s0);
    } else {
      // Branch-free, as in the real4 form: a missing neighbour reads the element itself with E = 0,
      // which zeroes its spring and dashpot exactly as the real4 form's factor `present` does.
      if (!run) jn = gather_int(grid, cell + offset);
      j = as_uint8(select(as_int8(e), jn, jn >= 0));
      gather4(u, j, &ujx, &ujy, &ujz, &wj);
      Ej = select((float8)0, gather(E, j), jn >= 0);
    }
    const float8 rx = h * VB_DIR[d][0] + (ujx - ui.x);
    const float8 ry = h * VB_DIR[d][1] + (ujy - ui.y);
    const float8 rz = h * VB_DIR[d][2] + (ujz - ui.z);
    const float8 len_sq = rx * rx + ry * ry + rz * rz;
    const float8 inv_len = select((float8)0, 1 / sqrt(len_sq), len_sq > 0);
    const float8 len = len_sq * inv_len;
    const float8 nx = rx * inv_len, ny = ry * inv_len, nz = rz * inv_len;
    const float rest = h * VB_DIR_LEN[d];
#if VB_DASHPOT
    const float8 w_sum = wi + wj;
    const float8 kE = VB_KAPPA[d] * h * (2 * Ei * Ej);
    const float8 q = 1 / ((Ei + Ej) * w_sum);
    const float8 k = kE * w_sum * q;
    float8 magnitude = k * (len - rest);
    float8 vjx, vjy, vjz, vjw;
    if (dense)
      load4_run(v, jn.s0, &vjx, &vjy, &vjz, &vjw);
    else
      gather4(v, j, &vjx, &vjy, &vjz, &vjw);
    magnitude += 2 * dashpot_ratio * sqrt(kE * q) * ((vjx - vi.x) * nx + (vjy - vi.y) * ny + (vjz - vi.z) * nz);
#else
    const float8 k = VB_KAPPA[d] * h * (2 * Ei * Ej / (Ei + Ej));
    const float8 magnitude = k * (len - rest);
#endif
    f.x += magnitude * nx;
    f.y += magnitude * ny;
    f.z += magnitude * nz;
  }
  return f;
}

// Acceleration of free elements (w = 1/m ≠ 0) from their lattice force: acceleration_from of
// kernels/integrate.cl without indenters.
VB_INLINE lanes3 lanes_acceleration(lanes3 f, float8 w, lanes3 vi, float4 gravity, float damping) {
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
  const lanes3 a = {f.x * w, f.y * w, f.z * w};
  return a;
}

// The kernels step the free elements only: work-item k the entries VB_LANE_WIDTH·k … of
// free_list (ascending; n_free of them, the list padded to a multiple of the width with its last
// entry, which the padding lanes compute and do not store). Held elements never change, so their
// entries in both state buffers stay as Simulator::upload wrote them. (On the phantom two thirds of
// the elements are the rigid chest wall.)

// The first of work-item k's elements in the free list, or n_free when it has none.
VB_INLINE uint lanes_first(uint n_free) {
  const uint first = (uint)get_global_id(0) * VB_LANE_WIDTH;
  return first < n_free ? first : n_free;
}

// One explicit stage of free elements (integrate.cl, explicit_stage): Heun's predictor
// ũ = u + dt·v, ṽ = v + dt·a(u, v), or a symplectic Euler step v' = v + dt·a(u, v), u' = u + dt·v'
// (`symplectic`, a constant at each call). With `relax` (a constant too; kernels/relax.cl:
// dynamic relaxation, symplectic) the acceleration is that of the fictitious dynamics,
// a·relax_scale − c·v, and v.w is 0 as relax_step stores it.
VB_INLINE void lanes_explicit_stage(global const float4* u, global const float4* v, global float4* u_out,
                                    global float4* v_out, VB_LATTICE_KERNEL_PARAMS, float dt, uint n_free,
                                    global const uint* free_list, int symplectic, int relax,
                                    global const float* relax_scale, float c, VB_LAG_PARAMS) {
  VB_UNPACK_LATTICE;
  const uint first = lanes_first(n_free);
  if (first == n_free) return;
  const uint8 e = vload8(0, free_list + first);
  lanes3 ui, vi;
  float8 wi, vw;
  gather4(u, e, &ui.x, &ui.y, &ui.z, &wi);
  gather4(v, e, &vi.x, &vi.y, &vi.z, &vw);
  lanes3 f = lanes_lattice_force(e, ui, wi, vi, u, v, E, cell_of, grid, sy, sz, h, dashpot_ratio);
  if (lag) {  // under the lagged constraint pressure (Heun's predicted stage, relaxation): integrate.cl's less_lag
    float8 gx, gy, gz, gw;
    gather4(lag_g, e, &gx, &gy, &gz, &gw);
    f.x = fma((float8)(-lag_p), gx, f.x);
    f.y = fma((float8)(-lag_p), gy, f.y);
    f.z = fma((float8)(-lag_p), gz, f.z);
  }
  lanes3 a = lanes_acceleration(f, wi, vi, gravity, damping);
  if (relax) {
    const float8 scale = gather(relax_scale, e);
    const lanes3 fictitious = {a.x * scale - c * vi.x, a.y * scale - c * vi.y, a.z * scale - c * vi.z};
    a = fictitious;
  }
  const lanes3 vn = {vi.x + dt * a.x, vi.y + dt * a.y, vi.z + dt * a.z};
  const lanes3 vm = symplectic ? vn : vi;  // the velocity the elements move with
  const lanes3 un = {ui.x + dt * vm.x, ui.y + dt * vm.y, ui.z + dt * vm.z};
  const uint count = min((uint)VB_LANE_WIDTH, n_free - first);
  scatter4(u_out, e, count, un.x, un.y, un.z, wi);
  scatter4(v_out, e, count, vn.x, vn.y, vn.z, relax ? (float8)0 : vw);
}

// The entries take the state as offsets into the state arena, as integrate.cl's (no obstacles
// here: indenters_at is unused).
kernel void heun_predict_lanes(VB_STEP_STATE_PARAMS, VB_LATTICE_KERNEL_PARAMS, VB_INDENTER_AT_PARAMS, real dt,
                               uint n_free, global const uint* free_list VB_LAG_KERNEL_PARAMS VB_STATE_PARAM) {
  lanes_explicit_stage(VB_STEP_STATE_POINTERS, VB_LATTICE_KERNEL_ARGS, dt, n_free, free_list, 0, 0, 0, 0,
                       VB_LAG_KERNEL_ARGS);
}

kernel void euler_step_lanes(VB_STEP_STATE_PARAMS, VB_LATTICE_KERNEL_PARAMS, VB_INDENTER_AT_PARAMS, real dt,
                             uint n_free, global const uint* free_list VB_STATE_PARAM) {
  lanes_explicit_stage(VB_STEP_STATE_POINTERS, VB_LATTICE_KERNEL_ARGS, dt, n_free, free_list, 1, 0, 0, 0, VB_NO_LAG);
}

// Heun's corrector: u' = u + dt/2·(v + ṽ), v' = (v + ṽ)/2 + dt/2·a(ũ, ṽ), forces from the predicted
// stage.
kernel void heun_correct_lanes(VB_STEP_STATE_PARAMS, VB_LATTICE_KERNEL_PARAMS, VB_INDENTER_AT_PARAMS, real dt,
                               uint n_free, global const uint* free_list VB_STATE_PARAM) {
  VB_UNPACK_LATTICE;
  const uint first = lanes_first(n_free);
  if (first == n_free) return;
  const uint8 e = vload8(0, free_list + first);
  global float4* u = VB_STATE_AT(float4, u_at);
  global float4* v = VB_STATE_AT(float4, v_at);
  global const float4* up_all = VB_STATE_AT(const float4, u_out_at);  // the predicted stage
  global const float4* vp_all = VB_STATE_AT(const float4, v_out_at);
  lanes3 ui, vi, up, vp;
  float8 wi, vw, wp, vwp;
  gather4(u, e, &ui.x, &ui.y, &ui.z, &wi);
  gather4(v, e, &vi.x, &vi.y, &vi.z, &vw);
  gather4(up_all, e, &up.x, &up.y, &up.z, &wp);
  gather4(vp_all, e, &vp.x, &vp.y, &vp.z, &vwp);
  const lanes3 a = lanes_acceleration(
      lanes_lattice_force(e, up, wi, vp, up_all, vp_all, E, cell_of, grid, sy, sz, h, dashpot_ratio), wi, vp, gravity,
      damping);
  const float mean = 0.5f, half_dt = 0.5f * dt;
  const lanes3 vn = {(vi.x + vp.x) * mean + half_dt * a.x, (vi.y + vp.y) * mean + half_dt * a.y,
                     (vi.z + vp.z) * mean + half_dt * a.z};
  const lanes3 un = {ui.x + half_dt * (vi.x + vp.x), ui.y + half_dt * (vi.y + vp.y), ui.z + half_dt * (vi.z + vp.z)};
  const uint count = min((uint)VB_LANE_WIDTH, n_free - first);
  scatter4(u, e, count, un.x, un.y, un.z, wi);
  scatter4(v, e, count, vn.x, vn.y, vn.z, (float8)0);
}

#endif
