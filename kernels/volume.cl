// Volume preservation (docs/PHYSICS.md, "Volume preservation"): a projection onto the constraint
// V(x) = V0, with V the volume enclosed by the surface mesh (docs/SURFACE.md) whose vertices are
// surface elements. Compiled only when the scene sets [volume] preserve = true (-DVB_VOLUME=1).
// All positions are in the lattice frame (rest_position + u), where V carries det(rotation).
//
//   volume_partials: per work-group partial sums (VB_VOLUME_SLOTS reals per group), one work-item
//   per surface element s
//     0  Σ x_s·g_s·2 (= 6V, positions relative to `centre`: V is homogeneous of degree 3 in them,
//        so Σ x_s·∂V/∂x_s = 3V by Euler's theorem; no pass over the triangles of its own)
//     1  Σ w|g|² over surface elements (w = 1/m, 0 for held elements; relaxation: 1/m̃)
//     2  Σ g·v over surface elements (the rate dV/dt)
//     3  Σ |g|² over free surface elements   4  Σ g·f over free surface elements (with_force only)
//   and g = ∂V/∂x of every surface element into `grad` (indexed by element).
//   volume_finish: one work-group; scalars = {λ, μ, V, p}: λ = (V0 − V)/Σw|g|², μ = Σg·v/Σw|g|²,
//     p = Σg·f/Σ|g|² (the pressure the check subtracts from the residual).
//   With VB_VOLUME_LAG (Heun and relaxation; kernels/integrate.cl, less_lag) the corrections
//     (volume_apply, volume_project) also update scalars[4], the multiplier M whose pressure M/dt
//     the next predicted stage (relaxation: the next step) feels; Heun M ← μ + M/2: at a
//     constrained equilibrium μ = dt·p − M/2, so M = dt·p is the fixed point, reached in one step
//     once the motion is quasi-static (relaxation: lag_update).
//   volume_apply: x += λ·w·g, v −= μ·w·g on the free surface elements; each of its work-groups
//     sums the partials itself (the same sums in the same order as volume_finish), so a
//     projection is two launches (partials, apply), not three.
//   volume_project: the whole projection in one launch. Each work-group adds its partial sums,
//     and the last one to finish (a count in global memory) sums them all (same order as
//     volume_finish), writes the scalars and applies x += λ·w·g, v −= μ·w·g to every free surface
//     element. Work-groups of VB_VOLUME_WG: wide on GPUs, where one group does the applying.
//   volume_pending (VB_VOLUME_FOLD, Heun only): volume_partials whose last work-group to finish
//     also computes the scalars (the same sums in the same order as volume_apply's), and nothing
//     is applied: the kernels that read the state next apply x + λ·w·g, v − μ·w·g on the fly
//     (VB_PENDING_PARAMS, kernels/common.cl), so a projection is one short launch.
#define VB_VOLUME_SLOTS 5

// Relaxation (kernels/relax.cl) moves elements by their fictitious masses m/relax_scale: its
// projection weights by the same masses. Weighted by the real ones, μ = (dt·p − M)·s̄ (s̄ a
// mean of relax_scale over the surface) and its lagged multiplier M ← M + μ diverged wherever
// s̄ > 2, e.g. soft tissue around a stiff core (test RelaxationVolume.ConvergesAroundAStiffCore).
#if VB_RELAX
#define VB_PROJECTION_PARAM , global const real *relax_scale
#define VB_PROJECTION_ARG , relax_scale
#define projection_w(w, e) ((w) * relax_scale[e])
#else
#define VB_PROJECTION_PARAM
#define VB_PROJECTION_ARG
#define projection_w(w, e) (w)
#endif
#if VB_VOLUME_PAIRS
#define VB_INCIDENT uint2
#else
#define VB_INCIDENT uint
#endif

inline real4 element_position(uint e, global const real4* u, global const uint* cell_of, int sy,
                              int sz, real4 origin, real h, real4 centre) {
  return rest_position(cell_of[e], sy, sz, origin, h) + xyz0(u[e]) - centre;
}

// Sums each slot of `value` over a work-group of `wg` items into s[k·wg] (every work-item must
// call it; s holds VB_VOLUME_SLOTS·wg reals).
inline void sum_over_group(local real* s, uint wg, const real* value, uint l) {
  for (int k = 0; k < VB_VOLUME_SLOTS; ++k) s[k * wg + l] = value[k];
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint stride = wg / 2; stride > 0; stride /= 2) {
    if (l < stride)
      for (int k = 0; k < VB_VOLUME_SLOTS; ++k) s[k * wg + l] += s[k * wg + l + stride];
    barrier(CLK_LOCAL_MEM_FENCE);
  }
}

// Work-item i's share of the partial sums: surface element i's terms, whose gradient g it writes
// to `grad`.
inline void volume_item_values(uint i, global const real4* u, global const real4* v, VB_LATTICE_PARAMS,
                               global const uint* triangles,
                               global const uint* surface_elements, global const uint* incident_start,
                               global const VB_INCIDENT* incident, uint n_surface, real4 centre,
                               global real4* grad, int with_force, real value[VB_VOLUME_SLOTS] VB_PROJECTION_PARAM) {
  for (int k = 0; k < VB_VOLUME_SLOTS; ++k) value[k] = 0;
  if (i < n_surface) {
    const uint e = surface_elements[i];
    // ∂(x0·(x1 × x2))/∂x0 = x1 × x2, cyclically. With VB_VOLUME_PAIRS incident[] holds, per
    // incident triangle, its two other corners' elements in cyclic order: each term is a chain of
    // two dependent loads (pair, then cell and u together). Without, it holds 3·triangle + corner:
    // four (corner, triangle, cell, u). Unrolled, the chains of several triangles overlap on a GPU
    // (the sum keeps its order; both forms give the same value).
    real4 g = 0;
    // (PoCL declines the unroll with a warning since these pointers come from the state arena;
    // CPUs overlap the chains without it.)
#if VB_NV_PTX
#pragma unroll 4
#endif
    for (uint k = incident_start[i]; k < incident_start[i + 1]; ++k) {
#if VB_VOLUME_PAIRS
      const uint2 bc = incident[k];
#else
      const uint t = incident[k] / 3, corner = incident[k] - 3 * t;
      const uint2 bc = (uint2)(triangles[3 * t + (corner + 1) % 3], triangles[3 * t + (corner + 2) % 3]);
#endif
      const real4 b = element_position(bc.x, u, cell_of, sy, sz, origin, h, centre);
      const real4 c = element_position(bc.y, u, cell_of, sy, sz, origin, h, centre);
      g += cross(b, c);
    }
    // each incident triangle's x0·(x1 × x2) once per corner: Σ_s x_s·(6g_s) = 3·6V
    value[0] = dot3(element_position(e, u, cell_of, sy, sz, origin, h, centre), g) / (real)3;
    g = xyz0(g) / (real)6;
    grad[e] = g;
    const real4 ui = u[e];
    value[1] = projection_w(ui.w, e) * dot3(g, g);
    value[2] = dot3(g, v[e]);
    if (with_force && ui.w != 0) {
      const real4 f = static_force(e, ui, v[e], u, v, VB_LATTICE_ARGS);
      value[3] = dot3(g, g);
      value[4] = dot3(g, f);
    }
  }
}

#define VB_VOLUME_MESH_PARAMS                                                                   \
  global const uint *triangles, global const uint *surface_elements,                            \
      global const uint *incident_start, global const VB_INCIDENT *incident, uint n_surface, real4 centre
#define VB_VOLUME_MESH_ARGS triangles, surface_elements, incident_start, incident, n_surface, centre
// What kernels take instead: the mesh's arrays in one buffer (engine/sim/device_arena.hpp), their
// offsets in `mesh_at` (triangles, surface elements, incident start, incident).
#define VB_VOLUME_MESH_KERNEL_PARAMS \
  global const uchar *mesh, uint4 mesh_at, uint n_surface, real4 centre
#define VB_UNPACK_SURFACE \
  global const uint* surface_elements = (global const uint*)VB_ARENA_AT(mesh, mesh_at.s1)
#define VB_UNPACK_MESH                                                                       \
  VB_UNPACK_SURFACE;                                                                         \
  global const uint* triangles = (global const uint*)VB_ARENA_AT(mesh, mesh_at.s0);          \
  global const uint* incident_start = (global const uint*)VB_ARENA_AT(mesh, mesh_at.s2);     \
  global const VB_INCIDENT* incident = (global const VB_INCIDENT*)VB_ARENA_AT(mesh, mesh_at.s3)

// Work-group `group`'s partial sums (VB_CHECK_WG items; every work-item of the group must call).
inline void volume_group_partials(uint group, global const real4* u, global const real4* v, VB_LATTICE_PARAMS,
                                  VB_VOLUME_MESH_PARAMS, global real4* grad, int with_force, global real* partial,
                                  local real* s VB_PROJECTION_PARAM) {
  const uint l = get_local_id(0);
  real value[VB_VOLUME_SLOTS];
  volume_item_values(group * VB_CHECK_WG + l, u, v, VB_LATTICE_ARGS, VB_VOLUME_MESH_ARGS, grad, with_force, value
                     VB_PROJECTION_ARG);
  sum_over_group(s, VB_CHECK_WG, value, l);
  if (l == 0)
    for (int k = 0; k < VB_VOLUME_SLOTS; ++k) partial[group * VB_VOLUME_SLOTS + k] = s[k * VB_CHECK_WG];
  barrier(CLK_LOCAL_MEM_FENCE);  // s is free again for the group's next call
}

// u, v, the gradient and the partial sums are state arena offsets (kernels/common.cl, VB_STATE_PARAM).
kernel __attribute__((reqd_work_group_size(VB_CHECK_WG, 1, 1)))
void volume_partials(uint u_at, uint v_at, VB_LATTICE_KERNEL_PARAMS, VB_VOLUME_MESH_KERNEL_PARAMS, uint grad_at,
                     int with_force, uint partial_at VB_PROJECTION_PARAM VB_STATE_PARAM) {
  VB_UNPACK_LATTICE;
  VB_UNPACK_MESH;
  global const real4* u = VB_STATE_AT(const real4, u_at);
  global const real4* v = VB_STATE_AT(const real4, v_at);
  global real4* grad = VB_STATE_AT(real4, grad_at);
  global real* partial = VB_STATE_AT(real, partial_at);
  local real s[VB_VOLUME_SLOTS * VB_CHECK_WG];
  volume_group_partials(get_group_id(0), u, v, VB_LATTICE_ARGS, VB_VOLUME_MESH_ARGS, grad, with_force, partial, s
                        VB_PROJECTION_ARG);
}

// λ, μ, V, p from the partial sums of `groups` work-groups of `wg` items (every work-item must call
// it; all get the result).
inline void volume_scalars(volatile global const real* partial, uint groups, real rest_volume, local real* s,
                           uint wg, uint l, real out[4]) {
  real value[VB_VOLUME_SLOTS];
  for (int k = 0; k < VB_VOLUME_SLOTS; ++k) value[k] = 0;
  for (uint g = l; g < groups; g += wg)
    for (int k = 0; k < VB_VOLUME_SLOTS; ++k) value[k] += partial[g * VB_VOLUME_SLOTS + k];
  sum_over_group(s, wg, value, l);
  const real volume = s[0] / (real)6, wgg = s[wg], gg = s[3 * wg];
  out[0] = wgg > 0 ? (rest_volume - volume) / wgg : 0;  // λ
  out[1] = wgg > 0 ? s[2 * wg] / wgg : 0;                // μ
  out[2] = volume;
  out[3] = gg > 0 ? s[4 * wg] / gg : 0;                  // p
}

kernel __attribute__((reqd_work_group_size(VB_CHECK_WG, 1, 1)))
void volume_finish(global const real* partial, uint groups, real rest_volume, global real* scalars) {
  local real s[VB_VOLUME_SLOTS * VB_CHECK_WG];
  const uint l = get_local_id(0);
  real out[4];
  volume_scalars(partial, groups, rest_volume, s, VB_CHECK_WG, l, out);
  if (l == 0)
    for (int k = 0; k < 4; ++k) scalars[k] = out[k];
}

// The lagged multiplier after a correction that removed μ (one work-item; nothing without VB_VOLUME_LAG).
// Heun: M ← μ + M/2 (its corrector averages two stages, only the predicted one feels M);
// relaxation: M ← M + μ (its one stage feels M; at equilibrium μ = dt·p − M, so M = dt·p).
inline void lag_update(global real* scalars, real mu) {
#if VB_VOLUME_LAG && VB_RELAX
  scalars[4] = mu + scalars[4];
#elif VB_VOLUME_LAG
  scalars[4] = mu + (real)0.5 * scalars[4];
#endif
}

// x += λ·w·g, v −= μ·w·g on free surface element e.
inline void volume_apply_one(uint e, global real4* u, global real4* v, real4 g, const real out[4] VB_PROJECTION_PARAM) {
  const real4 ui = u[e];
  if (ui.w == 0) return;
  const real4 wg = projection_w(ui.w, e) * g;
  u[e] = ui + out[0] * wg;
  v[e] = v[e] - out[1] * wg;
}

// u, v, the gradient, the partial sums and the scalars are state arena offsets.
kernel __attribute__((reqd_work_group_size(VB_CHECK_WG, 1, 1)))
void volume_apply(uint u_at, uint v_at, global const uchar* mesh, uint4 mesh_at, uint n_surface, uint grad_at,
                  uint partial_at, uint groups, real rest_volume, uint scalars_at VB_PROJECTION_PARAM VB_STATE_PARAM) {
  VB_UNPACK_SURFACE;
  global real4* u = VB_STATE_AT(real4, u_at);
  global real4* v = VB_STATE_AT(real4, v_at);
  global const real4* grad = VB_STATE_AT(const real4, grad_at);
  global const real* partial = VB_STATE_AT(const real, partial_at);
  global real* scalars = VB_STATE_AT(real, scalars_at);
  local real s[VB_VOLUME_SLOTS * VB_CHECK_WG];
  const uint i = get_global_id(0), l = get_local_id(0);
  real out[4];
  volume_scalars(partial, groups, rest_volume, s, VB_CHECK_WG, l, out);
  if (i == 0) {
    lag_update(scalars, out[1]);
    for (int k = 0; k < 4; ++k) scalars[k] = out[k];
  }
  if (i >= n_surface) return;
  const uint e = surface_elements[i];
  volume_apply_one(e, u, v, grad[e], out VB_PROJECTION_ARG);
}

// Each work-group's partial sums (and every surface element's g), then the group counts itself;
// true (in every work-item) in the last group to finish, which may then read all partials and
// gradients through volatile pointers (past the non-coherent L1 on NVIDIA).
inline int partials_counted(global const real4* u, global const real4* v, VB_LATTICE_PARAMS, VB_VOLUME_MESH_PARAMS,
                            global real4* grad, global real* partial, volatile global uint* groups_done,
                            local real* s, local int* last, uint wg VB_PROJECTION_PARAM) {
  const uint l = get_local_id(0);
  real value[VB_VOLUME_SLOTS];
  volume_item_values(get_global_id(0), u, v, VB_LATTICE_ARGS, VB_VOLUME_MESH_ARGS, grad, 0, value VB_PROJECTION_ARG);
  sum_over_group(s, wg, value, l);
  if (l == 0)
    for (int k = 0; k < VB_VOLUME_SLOTS; ++k) partial[get_group_id(0) * VB_VOLUME_SLOTS + k] = s[k * wg];
  // every work-item's g and the group's partials are globally visible before the group is counted
  barrier(CLK_GLOBAL_MEM_FENCE | CLK_LOCAL_MEM_FENCE);
  if (l == 0) {
    vb_device_fence();
    *last = atomic_inc(groups_done) == get_num_groups(0) - 1;
    vb_device_fence();
  }
  barrier(CLK_GLOBAL_MEM_FENCE | CLK_LOCAL_MEM_FENCE);
  return *last;
}

kernel __attribute__((reqd_work_group_size(VB_VOLUME_WG, 1, 1)))
void volume_project(global real4* u, global real4* v, VB_LATTICE_KERNEL_PARAMS, VB_VOLUME_MESH_KERNEL_PARAMS,
                    global real4* grad, global real* partial, real rest_volume, global real* scalars,
                    volatile global uint* groups_done VB_PROJECTION_PARAM) {
  VB_UNPACK_LATTICE;
  VB_UNPACK_MESH;
  local real s[VB_VOLUME_SLOTS * VB_VOLUME_WG];
  local int last;
  const uint l = get_local_id(0);
  if (!partials_counted(u, v, VB_LATTICE_ARGS, VB_VOLUME_MESH_ARGS, grad, partial, groups_done, s, &last,
                        VB_VOLUME_WG VB_PROJECTION_ARG))
    return;
  // The last group: the other groups' partials and gradients are read past any cache (volatile).
  real out[4];
  volume_scalars(partial, get_num_groups(0), rest_volume, s, VB_VOLUME_WG, l, out);
  volatile global const real4* g_all = grad;
  // four elements per round, all loads before the stores, so their latencies overlap
  for (uint base = l; base < n_surface; base += 4 * VB_VOLUME_WG) {
    uint e[4];
    real4 g[4];
    for (int r = 0; r < 4; ++r) {
      const uint k = base + r * VB_VOLUME_WG;
      e[r] = k < n_surface ? surface_elements[k] : 0xffffffffu;
    }
    for (int r = 0; r < 4; ++r) g[r] = e[r] != 0xffffffffu ? g_all[e[r]] : (real4)(0);
    for (int r = 0; r < 4; ++r)
      if (e[r] != 0xffffffffu) volume_apply_one(e[r], u, v, g[r], out VB_PROJECTION_ARG);
  }
  if (l == 0) {
    lag_update(scalars, out[1]);
    for (int k = 0; k < 4; ++k) scalars[k] = out[k];
    *groups_done = 0;  // ready for the next launch
  }
}

#if VB_VOLUME_FOLD
// The projection of (u, v) left pending (see the top of this file): the gradient into `grad`, and
// λ, μ, V, p into `scalars` by the last work-group, summed as volume_apply sums them (work-groups
// of VB_CHECK_WG, so the same partials in the same order: the same values as the two-launch form).
kernel __attribute__((reqd_work_group_size(VB_CHECK_WG, 1, 1)))
void volume_pending(global const real4* u, global const real4* v, VB_LATTICE_KERNEL_PARAMS, VB_VOLUME_MESH_KERNEL_PARAMS,
                    global real4* grad, global real* partial, real rest_volume, global real* scalars,
                    volatile global uint* groups_done VB_PROJECTION_PARAM) {
  VB_UNPACK_LATTICE;
  VB_UNPACK_MESH;
  local real s[VB_VOLUME_SLOTS * VB_CHECK_WG];
  local int last;
  const uint l = get_local_id(0);
  if (!partials_counted(u, v, VB_LATTICE_ARGS, VB_VOLUME_MESH_ARGS, grad, partial, groups_done, s, &last,
                        VB_CHECK_WG VB_PROJECTION_ARG))
    return;
  real out[4];
  volume_scalars(partial, get_num_groups(0), rest_volume, s, VB_CHECK_WG, l, out);
  if (l == 0) {
    for (int k = 0; k < 4; ++k) scalars[k] = out[k];
    *groups_done = 0;  // ready for the next launch
  }
}
#endif
