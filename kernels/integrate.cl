// Time integrators. One work-item per element; held elements (u.w == 0) never move.
// With VB_TORI the torus device (kernels/device_contact.cl) constrains each stage's acceleration
// (a = f/m: removing its inward normal part removes the force's), applies friction to the new
// velocity and projects the stage's end out of the tubes, after the indenters (finish_stage).
//   symplectic Euler (main paper eq. 11):  v' = v + dt·a(u, v);  u' = u + dt·v'
//   Heun (improved Euler, trapezium rule): predictor ũ = u + dt·v, ṽ = v + dt·a(u, v);
//     corrector u' = u + dt/2·(v + ṽ), v' = v + dt/2·(a(u, v) + a(ũ, ṽ)) = (v + ṽ)/2 + dt/2·a(ũ, ṽ)
//     (a(u, v) is recovered from ṽ, so no force buffer is stored).

// `grip` collects the indenters' friction (device_contact.cl), turned into m/s² like the torus's.
// The neighbours' u, v are read as a pending volume projection leaves them (kernels/common.cl).
inline real4 acceleration_pending(uint e, real4 ui, real4 vi, global const real4* u, global const real4* v,
                                  VB_LATTICE_PARAMS, global const real* indenters, real t, torus_grip* grip,
                                  VB_PENDING_PARAMS) {
  real4 f = static_force_pending(e, ui, vi, u, v, VB_LATTICE_ARGS, VB_PENDING_ARGS);
#if VB_GLOBAL_DAMPING
  f -= damping * xyz0(vi) / ui.w;
#endif
#if VB_INDENTERS
  contact_constrain_all(&f, rest_position(cell_of[e], sy, sz, origin, h) + xyz0(ui), indenters, t, h, grip);
#endif
  grip->grip_n *= ui.w;
  return f * ui.w;
}

inline real4 acceleration(uint e, real4 ui, real4 vi, global const real4* u, global const real4* v,
                          VB_LATTICE_PARAMS, global const real* indenters, real t, torus_grip* grip) {
  return acceleration_pending(e, ui, vi, u, v, VB_LATTICE_ARGS, indenters, t, grip, VB_NO_PENDING);
}

// Ends a stage: moves an element that ended inside an indenter or a torus tube back onto its
// surface (indenters first; the obstacle table holds both).
inline void finish_stage(uint e, real4* un, real4* vn, global const uint* cell_of, int sy, int sz,
                         real4 origin, real h, global const real* indenters, real t) {
#if VB_INDENTERS || VB_TORI
  const real4 X = rest_position(cell_of[e], sy, sz, origin, h);
#endif
#if VB_INDENTERS
  contact_project_all(un, vn, X, indenters, t, h);
#endif
#if VB_TORI
  torus_project_all(un, vn, X, indenters, t, h);
#endif
}

// One explicit stage from (u, v): symplectic Euler updates v first and moves with the new v;
// Heun's predictor (explicit Euler) moves with the old v. `symplectic` is a constant at each call.
// (u, v) may have a volume projection pending (kernels/common.cl): the stage starts from the
// projected state, its own included.
inline void explicit_stage(global const real4* u, global const real4* v, global real4* u_out,
                           global real4* v_out, VB_LATTICE_PARAMS, VB_INDENTER_PARAMS, real dt,
                           uint n, int symplectic, VB_PENDING_PARAMS) {
  const uint e = get_global_id(0);
  if (e >= n) return;
  real4 ui = u[e], vi = v[e], wg = (real4)(0);
  pending_u(&ui, &wg, e, VB_PENDING_ARGS);
  pending_v(&vi, wg, VB_PENDING_ARGS);
  if (ui.w != 0) {
    torus_grip grip = {0};  // friction of the indenters and tori (no-op without VB_FRICTION)
    real4 a = acceleration_pending(e, ui, vi, u, v, VB_LATTICE_ARGS, indenters, t_force, &grip, VB_PENDING_ARGS);
#if VB_TORI
    const real4 X = rest_position(cell_of[e], sy, sz, origin, h);
    torus_constrain_all(&a, X + xyz0(ui), indenters, t_force, h, &grip);
#endif
    if (symplectic) vi += dt * a;
    if (symplectic) torus_apply_grip(&vi, grip, dt);
    ui += dt * xyz0(vi);
    if (!symplectic) vi += dt * a;
    if (!symplectic) torus_apply_grip(&vi, grip, dt);
    finish_stage(e, &ui, &vi, cell_of, sy, sz, origin, h, indenters, t_project);
  }
  u_out[e] = ui;
  v_out[e] = vi;
}

kernel void euler_step(global const real4* u, global const real4* v, global real4* u_out,
                       global real4* v_out, VB_LATTICE_PARAMS, VB_INDENTER_PARAMS, real dt,
                       uint n) {
  explicit_stage(u, v, u_out, v_out, VB_LATTICE_ARGS, VB_INDENTER_ARGS, dt, n, 1, VB_NO_PENDING);
}

// With VB_VOLUME_FOLD (Heun with the volume constraint, kernels/volume.cl: volume_pending) the
// stepping kernels take the pending projections' gradients and scalars {λ, μ, …} (zero scalars
// when none is pending): heun_predict that of (u, v); heun_correct that of (u, v) for the element's
// own u, v and that of the predicted stage (ũ, ṽ) for every read of it.
#if VB_VOLUME_FOLD
#define VB_FOLD_PARAMS(name) , global const real4 *name##_g, global const real *name##_scalars
#define VB_FOLD_PENDING(name) name##_g, name##_scalars[0], name##_scalars[1], 1
#else
#define VB_FOLD_PARAMS(name)
#define VB_FOLD_PENDING(name) VB_NO_PENDING
#endif

kernel void heun_predict(global const real4* u, global const real4* v, global real4* u_pred,
                         global real4* v_pred, VB_LATTICE_PARAMS, VB_INDENTER_PARAMS, real dt,
                         uint n VB_FOLD_PARAMS(state)) {
  explicit_stage(u, v, u_pred, v_pred, VB_LATTICE_ARGS, VB_INDENTER_ARGS, dt, n, 0, VB_FOLD_PENDING(state));
}

kernel void heun_correct(global real4* u, global real4* v, global const real4* u_pred,
                         global const real4* v_pred, VB_LATTICE_PARAMS, VB_INDENTER_PARAMS,
                         real dt, uint n VB_FOLD_PARAMS(state) VB_FOLD_PARAMS(pred)) {
  const uint e = get_global_id(0);
  if (e >= n) return;
  real4 ui = u[e];
  if (ui.w == 0) return;
  real4 vi = v[e], up = u_pred[e], vp = v_pred[e], wg = (real4)(0), wgp = (real4)(0);
  pending_u(&ui, &wg, e, VB_FOLD_PENDING(state));
  pending_v(&vi, wg, VB_FOLD_PENDING(state));
  pending_u(&up, &wgp, e, VB_FOLD_PENDING(pred));
  pending_v(&vp, wgp, VB_FOLD_PENDING(pred));
  torus_grip grip = {0};
  real4 a = acceleration_pending(e, up, vp, u_pred, v_pred, VB_LATTICE_ARGS, indenters, t_force, &grip,
                                 VB_FOLD_PENDING(pred));
#if VB_TORI
  const real4 X = rest_position(cell_of[e], sy, sz, origin, h);
  torus_constrain_all(&a, X + xyz0(up), indenters, t_force, h, &grip);
#endif
  real4 vn = xyz0((vi + vp) * (real)0.5 + (real)0.5 * dt * a);
  torus_apply_grip(&vn, grip, (real)0.5 * dt);  // the predictor's half reaches vn through ṽ
  ui += (real)0.5 * dt * xyz0(vi + vp);
  finish_stage(e, &ui, &vn, cell_of, sy, sz, origin, h, indenters, t_project);
  u[e] = ui;
  v[e] = vn;
}
