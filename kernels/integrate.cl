// Time integrators. One work-item per element; held elements (u.w == 0) never move.
// With VB_TORI the torus device (kernels/device_contact.cl) constrains each stage's acceleration
// (a = f/m: removing its inward normal part removes the force's), applies friction to the new
// velocity and projects the stage's end out of the tubes, after the indenters (finish_stage).
//   symplectic Euler (main paper eq. 11):  v' = v + dt·a(u, v);  u' = u + dt·v'
//   Heun (improved Euler, trapezium rule): predictor ũ = u + dt·v, ṽ = v + dt·a(u, v);
//     corrector u' = u + dt/2·(v + ṽ), v' = v + dt/2·(a(u, v) + a(ũ, ṽ)) = (v + ṽ)/2 + dt/2·a(ũ, ṽ)
//     (a(u, v) is recovered from ṽ, so no force buffer is stored).

// Heun's predicted stage under the volume constraint's lagged pressure (VB_VOLUME_LAG; Simulator:
// volume_lag_; docs/PHYSICS.md, "Volume preservation"): instead of a projection of its own, the
// stage feels the force −(M/dt)·g on each free surface element, g the volume gradient and M the
// multiplier the last corrections left (kernels/volume.cl: M ← μ + M/2), so at a constrained
// equilibrium ṽ = v + dt·w·(f − p·g) = 0, as with the projection. less_lag subtracts that force
// from the lattice force f, as one fused multiply-add, so that the CPU lanes kernels
// (integrate_lanes.cl), which do it on float8 vectors, round it identically whatever the
// compiler contracts; with `lag` 0 (a constant at each call) it costs nothing.
#define VB_LAG_PARAMS int lag, global const real4 *lag_g, real lag_p
#define VB_LAG_ARGS lag, lag_g, lag_p
#define VB_NO_LAG 0, (global const real4*)0, (real)0
VB_INLINE real4 less_lag(real4 f, uint e, VB_LAG_PARAMS) { return lag ? fma((real4)(-lag_p), lag_g[e], f) : f; }
// heun_predict's own arguments: the gradient and the volume scalars {λ, μ, V, p, M} (state arena
// offsets).
#if VB_VOLUME_LAG
#define VB_LAG_KERNEL_PARAMS , uint lag_g_at, uint lag_scalars_at
#define VB_LAG_KERNEL_ARGS 1, VB_STATE_AT(const real4, lag_g_at), VB_STATE_AT(const real, lag_scalars_at)[4] / dt
#else
#define VB_LAG_KERNEL_PARAMS
#define VB_LAG_KERNEL_ARGS VB_NO_LAG
#endif

// Acceleration of free element e from its lattice force f (N): gravity, global damping and the
// indenters' constraint added as static_force and acceleration add them. The stage ends near
// x + lead·v + gain·a (the push indenters' landing rule: contact_constrain).
// `grip` collects the indenters' friction (device_contact.cl), turned into m/s² like the torus's.
// With VB_TRI_CONTACT the triangle-contact forces (triangle_contact.cl, computed for the same u
// just before this kernel) are added, and with friction their grip; VB_TRI_PARAMS is empty otherwise.
VB_INLINE real4 acceleration_from(real4 f, uint e, real4 ui, real4 vi, VB_LATTICE_PARAMS,
                                  global const real* indenters, real t, real lead, real gain,
                                  torus_grip* grip VB_TRI_PARAMS) {
#if VB_GRAVITY
  f += xyz0(gravity) / ui.w;
#endif
#if VB_TRI_CONTACT
  f += triangle_contact_all(e, indenters, t, grip, corner_force, tri_start, tri_corner, n_tri);  // computed for this u
#endif
#if VB_GLOBAL_DAMPING
  f -= damping * xyz0(vi) / ui.w;
#endif
#if VB_INDENTERS
  contact_constrain_all(&f, rest_position(cell_of[e], sy, sz, origin, h) + xyz0(ui), vi, lead, gain * ui.w, indenters, t,
                        h, grip);
#endif
  grip->grip_n *= ui.w;
  return f * ui.w;
}

// Ends a stage: moves an element that ended inside an indenter or a torus tube back onto its
// surface (indenters first; the obstacle table holds both).
// u_start is the element's displacement where the stage began, at t_start (held contacts).
VB_INLINE void finish_stage(uint e, real4* un, real4* vn, real4 u_start, global const uint* cell_of, int sy, int sz,
                            real4 origin, real h, global const real* indenters, real t_start, real t) {
#if VB_INDENTERS || VB_TORI
  const real4 X = rest_position(cell_of[e], sy, sz, origin, h);
#endif
#if VB_INDENTERS
  contact_project_all(un, vn, X, X + xyz0(u_start), indenters, t_start, t, h);
#endif
#if VB_TORI
  torus_project_all(un, vn, X, indenters, t, h);
#endif
}

// The end of an explicit stage of free element e once its lattice force f is known.
VB_INLINE void explicit_update(uint e, real4* ui, real4* vi, real4 f, VB_LATTICE_PARAMS, VB_INDENTER_PARAMS,
                               real dt, int symplectic VB_TRI_PARAMS) {
  torus_grip grip = {0};  // friction of the indenters and tori (no-op without VB_FRICTION)
  const real4 u_start = *ui;
  // the stage ends at u + dt·v + dt²·a (symplectic) or, through ṽ, at Heun's u' = u + dt·v + dt²/2·a
  const real gain = (symplectic ? (real)1 : (real)0.5) * dt * dt;
  real4 a = acceleration_from(f, e, *ui, *vi, VB_LATTICE_ARGS, indenters, t_force, dt, gain, &grip VB_TRI_ARGS);
#if VB_TORI
  const real4 X = rest_position(cell_of[e], sy, sz, origin, h);
  torus_constrain_all(&a, X + xyz0(*ui), *vi, dt, gain, indenters, t_force, h, &grip);
#endif
  if (symplectic) *vi += dt * a;
  if (symplectic) torus_apply_grip(vi, grip, dt);
  *ui += dt * xyz0(*vi);
  if (!symplectic) *vi += dt * a;
  if (!symplectic) torus_apply_grip(vi, grip, dt);
  finish_stage(e, ui, vi, u_start, cell_of, sy, sz, origin, h, indenters, t_force, t_project);
}

// The corrector's end for free element e once the lattice force f at (ũ, ṽ) is known: returns v',
// moves ui to u'.
VB_INLINE real4 correct_update(uint e, real4* ui, real4 vi, real4 up, real4 vp, real4 f, VB_LATTICE_PARAMS,
                               VB_INDENTER_PARAMS, real dt VB_TRI_PARAMS) {
  torus_grip grip = {0};
  const real gain = (real)0.5 * dt * dt;  // as the predictor's
  real4 a = acceleration_from(f, e, up, vp, VB_LATTICE_ARGS, indenters, t_force, dt, gain, &grip VB_TRI_ARGS);
#if VB_TORI
  const real4 X = rest_position(cell_of[e], sy, sz, origin, h);
  torus_constrain_all(&a, X + xyz0(up), vp, dt, gain, indenters, t_force, h, &grip);
#endif
  real4 vn = xyz0((vi + vp) * (real)0.5 + (real)0.5 * dt * a);
  torus_apply_grip(&vn, grip, (real)0.5 * dt);  // the predictor's half reaches vn through ṽ
  *ui += (real)0.5 * dt * xyz0(vi + vp);
  finish_stage(e, ui, &vn, up, cell_of, sy, sz, origin, h, indenters, t_force, t_project);
  return vn;
}

// VB_SPLIT > 1 (Heun on GPUs, small hyperelastic models; --plan force_split): each element's 26
// connections are summed by VB_SPLIT work-items, a group of VB_SPLIT_WG holding VB_SPLIT_PER
// elements, part p in work-items p·VB_SPLIT_PER + i (whole warps per part, so the range of
// connections is uniform in a warp). Part 0 adds the other parts' sums from local memory in a fixed
// order (deterministic) and finishes the element. More threads for a latency-bound pass at sizes
// that fill a GPU only a few warps deep.
#if VB_SPLIT > 1
#define VB_SPLIT_WG 128
#define VB_SPLIT_PER (VB_SPLIT_WG / VB_SPLIT)
#define VB_STEP_ATTR __attribute__((reqd_work_group_size(VB_SPLIT_WG, 1, 1)))
inline uint split_element(uint block) { return block * VB_SPLIT_PER + get_local_id(0) % VB_SPLIT_PER; }

// The lattice force on e summed over the parts (in part 0; every work-item of the group must call).
VB_INLINE real4 split_lattice_force(int active, uint e, real4 ui, real4 vi, global const real4* u, global const real4* v,
                                    VB_LATTICE_PARAMS, VB_PENDING_PARAMS, local real4* share) {
  const uint l = get_local_id(0), part = l / VB_SPLIT_PER;
  real4 f = (real4)(0);
  if (active)
    f = lattice_force_pending(e, ui, vi, u, v, VB_LATTICE_ARGS, VB_PENDING_ARGS, (int)(26 * part / VB_SPLIT),
                              (int)(26 * (part + 1) / VB_SPLIT), 0, u);
  if (part) share[l] = f;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (!part)
    for (int p = 1; p < VB_SPLIT; ++p) f += share[l + p * VB_SPLIT_PER];
  return f;
}
#else
#define VB_STEP_ATTR
#endif

// One explicit stage from (u, v): symplectic Euler updates v first and moves with the new v;
// Heun's predictor (explicit Euler) moves with the old v. `symplectic` and `pack` (the stage
// written packed: Heun's predictor with VB_PRED_PACKED) are constants at each call.
// (u, v) may have a volume projection pending (kernels/common.cl): the stage starts from the
// projected state, its own included.
VB_INLINE void explicit_stage(uint e, global const real4* u, global const real4* v, global real4* u_out,
                              global real4* v_out, VB_LATTICE_PARAMS, VB_INDENTER_PARAMS, real dt,
                              uint n, int symplectic, int pack, VB_PENDING_PARAMS, VB_LAG_PARAMS VB_TRI_PARAMS) {
  if (e >= n) return;
  real4 ui = u[e], vi = v[e], wg = (real4)(0);
  pending_u(&ui, &wg, e, VB_PENDING_ARGS);
  pending_v(&vi, wg, VB_PENDING_ARGS);
  if (ui.w != 0) {
    const real4 f =
        less_lag(lattice_force_pending(e, ui, vi, u, v, VB_LATTICE_ARGS, VB_PENDING_ARGS, 0, 26, 0, u), e, VB_LAG_ARGS);
    explicit_update(e, &ui, &vi, f, VB_LATTICE_ARGS, VB_INDENTER_ARGS, dt, symplectic VB_TRI_ARGS);
  }
  stage_store(u_out, v_out, e, pack, ui, vi);
}

// The stepping kernels' entries take u, v and where the stage goes as state arena offsets
// (kernels/common.cl, VB_STATE_PARAM).
#define VB_UNPACK_STEP_STATE(in_const, out_const)                       \
  VB_UNPACK_INDENTERS;                                                  \
  in_const global real4* u = VB_STATE_AT(real4, u_at);                  \
  in_const global real4* v = VB_STATE_AT(real4, v_at);                  \
  out_const global real4* u_out = VB_STATE_AT(real4, u_out_at);         \
  out_const global real4* v_out = VB_STATE_AT(real4, v_out_at)
#define VB_STEP_STATE_PARAMS uint u_at, uint v_at, uint u_out_at, uint v_out_at
// The same four arrays as pointer arguments of a helper (the lanes kernels').
#define VB_STEP_STATE_POINTERS                                                                  \
  VB_STATE_AT(const real4, u_at), VB_STATE_AT(const real4, v_at), VB_STATE_AT(real4, u_out_at), \
      VB_STATE_AT(real4, v_out_at)

kernel void euler_step(VB_STEP_STATE_PARAMS, VB_LATTICE_KERNEL_PARAMS, VB_INDENTER_AT_PARAMS, real dt,
                       uint n VB_TRI_PARAMS VB_STATE_PARAM) {
  VB_UNPACK_LATTICE;
  VB_UNPACK_STEP_STATE(const, );
  explicit_stage(VB_STEP_INDEX(get_global_id(0)), u, v, u_out, v_out, VB_LATTICE_ARGS, VB_INDENTER_ARGS, dt,
                 VB_STEP_N, 1, 0, VB_NO_PENDING, VB_NO_LAG VB_TRI_ARGS);
}

// With VB_VOLUME_FOLD (Heun with the volume constraint, kernels/volume.cl: volume_pending) the
// stepping kernels take the pending projections' gradients and scalars {λ, μ, …} (zero scalars
// when none is pending): heun_predict that of (u, v); heun_correct that of (u, v) for the element's
// own u, v and that of the predicted stage (ũ, ṽ) for every read of it.
#if VB_VOLUME_FOLD
#define VB_FOLD_PARAMS(name) , uint name##_g_at, uint name##_scalars_at
#define VB_FOLD_PENDING(name)                                                                          \
  VB_STATE_AT(const real4, name##_g_at), VB_STATE_AT(const real, name##_scalars_at)[0],                \
      VB_STATE_AT(const real, name##_scalars_at)[1], 1
#else
#define VB_FOLD_PARAMS(name)
#define VB_FOLD_PENDING(name) VB_NO_PENDING
#endif

// Heun's predictor for element e (ũ, ṽ into u_pred, v_pred). With VB_SPLIT > 1 every work-item of
// the group calls it, e = split_element(block), and `share` holds VB_SPLIT_WG real4.
VB_INLINE void predict_element(uint e, global const real4* u, global const real4* v, global real4* u_pred,
                               global real4* v_pred, VB_LATTICE_PARAMS, VB_INDENTER_PARAMS, real dt, uint n,
                               VB_PENDING_PARAMS, VB_LAG_PARAMS, local real4* share VB_TRI_PARAMS) {
#if VB_SPLIT > 1
  const int in = e < n;
  real4 ui = (real4)(0), vi = (real4)(0), wg = (real4)(0);
  if (in) {
    ui = u[e];
    vi = v[e];
    pending_u(&ui, &wg, e, VB_PENDING_ARGS);
    pending_v(&vi, wg, VB_PENDING_ARGS);
  }
  const real4 f = split_lattice_force(in && ui.w != 0, e, ui, vi, u, v, VB_LATTICE_ARGS, VB_PENDING_ARGS, share);
  if (!in || get_local_id(0) >= VB_SPLIT_PER) return;
  if (ui.w != 0)
    explicit_update(e, &ui, &vi, less_lag(f, e, VB_LAG_ARGS), VB_LATTICE_ARGS, VB_INDENTER_ARGS, dt, 0 VB_TRI_ARGS);
  u_pred[e] = ui;
  v_pred[e] = vi;
#else
  explicit_stage(e, u, v, u_pred, v_pred, VB_LATTICE_ARGS, VB_INDENTER_ARGS, dt, n, 0, VB_PRED_PACKED, VB_PENDING_ARGS,
                 VB_LAG_ARGS VB_TRI_ARGS);
#endif
}

// Heun's corrector for element e (u', v' into u, v; the same calling rule as predict_element):
// `pending` of the state (u, v) for the element's own u, v, and pred_* of the predicted stage.
// The element's own u, v are read after the force loop, so they are not live across it (fewer
// registers); the held test reads ũ.w, which the predictor copies from u
// (packed, VB_PRED_PACKED: u.w itself).
VB_INLINE void correct_element(uint e, global real4* u, global real4* v, global const real4* u_pred,
                               global const real4* v_pred, VB_LATTICE_PARAMS, VB_INDENTER_PARAMS, real dt, uint n,
                               VB_PENDING_PARAMS, global const real4* pred_g, real pred_lambda, real pred_mu,
                               int pred_pending, local real4* share VB_TRI_PARAMS) {
  const int in = e < n;
#if VB_SPLIT == 1
  if (!in) return;
#endif
  real4 up = (real4)(0), vp = (real4)(0), wgp = (real4)(0);
  if (in) {
    stage_load(u_pred, v_pred, e, VB_PRED_PACKED, u, &up, &vp);
    pending_u(&up, &wgp, e, pred_g, pred_lambda, pred_mu, pred_pending);
    pending_v(&vp, wgp, pred_g, pred_lambda, pred_mu, pred_pending);
  }
#if VB_SPLIT > 1
  const real4 f = split_lattice_force(in && up.w != 0, e, up, vp, u_pred, v_pred, VB_LATTICE_ARGS, pred_g,
                                      pred_lambda, pred_mu, pred_pending, share);
  if (!in || get_local_id(0) >= VB_SPLIT_PER) return;
  if (up.w == 0) return;
#else
  if (up.w == 0) return;
  const real4 f = lattice_force_pending(e, up, vp, u_pred, v_pred, VB_LATTICE_ARGS, pred_g, pred_lambda, pred_mu,
                                        pred_pending, 0, 26, VB_PRED_PACKED, u);
#endif
  real4 ui = u[e], vi = v[e], wg = (real4)(0);
  pending_u(&ui, &wg, e, VB_PENDING_ARGS);
  pending_v(&vi, wg, VB_PENDING_ARGS);
  const real4 vn = correct_update(e, &ui, vi, up, vp, f, VB_LATTICE_ARGS, VB_INDENTER_ARGS, dt VB_TRI_ARGS);
  u[e] = ui;
  v[e] = vn;
}

#if VB_SPLIT > 1
#define VB_STEP_ELEMENT split_element(get_group_id(0))
#define VB_STEP_SHARE local real4 share[VB_SPLIT_WG]
#else
#define VB_STEP_ELEMENT VB_STEP_INDEX(get_global_id(0))
#define VB_STEP_SHARE local real4* share = 0
#endif

kernel VB_STEP_ATTR void heun_predict(VB_STEP_STATE_PARAMS, VB_LATTICE_KERNEL_PARAMS, VB_INDENTER_AT_PARAMS, real dt,
                                      uint n VB_FOLD_PARAMS(state) VB_LAG_KERNEL_PARAMS VB_TRI_PARAMS
                                          VB_STATE_PARAM) {
  VB_UNPACK_LATTICE;
  VB_UNPACK_STEP_STATE(const, );
  VB_STEP_SHARE;
  predict_element(VB_STEP_ELEMENT, u, v, u_out, v_out, VB_LATTICE_ARGS, VB_INDENTER_ARGS, dt, VB_STEP_N,
                  VB_FOLD_PENDING(state), VB_LAG_KERNEL_ARGS, share VB_TRI_ARGS);
}

// VB_CORRECT_REVERSE (Simulator::correct_reverse_, engine/sim/correct_order.hpp): heun_correct
// takes the elements' aligned blocks of VB_REVERSE_BLOCK (the short loop's lockstep, so a warp
// still holds one block of marks) from the last to the first, each block in order. It then starts
// on the lines heun_predict wrote last, still in L2, and ends on the elements the next
// heun_predict starts with (H200, linear cubes of 1.0M-1.5M elements: 4-5% more steps/s, both
// stages reading 17-45% less from DRAM; docs/PERFORMANCE.md, "Work-group sizes"). Each
// element's arithmetic is its own, so the order changes no result.
#ifndef VB_CORRECT_REVERSE
#define VB_CORRECT_REVERSE 0
#endif
#if VB_CORRECT_REVERSE
#if VB_SPLIT > 1 || VB_STEP_LIST || VB_LANES || VB_PERSISTENT
#error "VB_CORRECT_REVERSE: one work-item per element, in the elements' own order, only"
#endif
#define VB_CORRECT_ELEMENT reverse_block_element(get_global_id(0), n, VB_REVERSE_BLOCK)
#else
#define VB_CORRECT_ELEMENT VB_STEP_ELEMENT
#endif

// heun_correct reads the predicted stage from u_out_at, v_out_at and writes u, v.
kernel VB_STEP_ATTR void heun_correct(VB_STEP_STATE_PARAMS, VB_LATTICE_KERNEL_PARAMS, VB_INDENTER_AT_PARAMS, real dt,
                                      uint n VB_FOLD_PARAMS(state) VB_FOLD_PARAMS(pred) VB_TRI_PARAMS
                                          VB_STATE_PARAM) {
  VB_UNPACK_LATTICE;
  VB_UNPACK_STEP_STATE(, const);
  VB_STEP_SHARE;
  correct_element(VB_CORRECT_ELEMENT, u, v, u_out, v_out, VB_LATTICE_ARGS, VB_INDENTER_ARGS, dt, VB_STEP_N,
                  VB_FOLD_PENDING(state), VB_FOLD_PENDING(pred), share VB_TRI_ARGS);
}
