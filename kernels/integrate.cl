// Time integrators. One work-item per element; held elements (u.w == 0) never move.
// With VB_TORI the torus device (kernels/device_contact.cl) constrains each stage's acceleration
// (a = f/m: removing its inward normal part removes the force's), applies friction to the new
// velocity and projects the stage's end out of the tubes, after the indenters (finish_stage).
//   symplectic Euler (main paper eq. 11):  v' = v + dt·a(u, v);  u' = u + dt·v'
//   Heun (improved Euler, trapezium rule): predictor ũ = u + dt·v, ṽ = v + dt·a(u, v);
//     corrector u' = u + dt/2·(v + ṽ), v' = v + dt/2·(a(u, v) + a(ũ, ṽ)) = (v + ṽ)/2 + dt/2·a(ũ, ṽ)
//     (a(u, v) is recovered from ṽ, so no force buffer is stored).

// `grip` collects the indenters' friction (device_contact.cl), turned into m/s² like the torus's.
// With VB_TRI_CONTACT the triangle-contact forces (triangle_contact.cl, computed for the same u
// just before this kernel) are added; VB_TRI_PARAMS is empty otherwise.
inline real4 acceleration(uint e, real4 ui, real4 vi, global const real4* u, global const real4* v,
                          VB_LATTICE_PARAMS, global const real* indenters, real t, torus_grip* grip VB_TRI_PARAMS) {
  real4 f = static_force(e, ui, vi, u, v, VB_LATTICE_ARGS);
#if VB_TRI_CONTACT
  f += triangle_contact_all(e, indenters, corner_force, tri_start, tri_corner, n_tri);  // computed for this u
#endif
#if VB_GLOBAL_DAMPING
  f -= damping * xyz0(vi) / ui.w;
#endif
#if VB_INDENTERS
  contact_constrain_all(&f, rest_position(cell_of[e], sy, sz, origin, h) + xyz0(ui), indenters, t, h, grip);
#endif
  grip->grip_n *= ui.w;
  return f * ui.w;
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
inline void explicit_stage(global const real4* u, global const real4* v, global real4* u_out,
                           global real4* v_out, VB_LATTICE_PARAMS, VB_INDENTER_PARAMS, real dt,
                           uint n, int symplectic VB_TRI_PARAMS) {
  const uint e = get_global_id(0);
  if (e >= n) return;
  real4 ui = u[e], vi = v[e];
  if (ui.w != 0) {
    torus_grip grip = {0};  // friction of the indenters and tori (no-op without VB_FRICTION)
    real4 a = acceleration(e, ui, vi, u, v, VB_LATTICE_ARGS, indenters, t_force, &grip VB_TRI_ARGS);
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
                       uint n VB_TRI_PARAMS) {
  explicit_stage(u, v, u_out, v_out, VB_LATTICE_ARGS, VB_INDENTER_ARGS, dt, n, 1 VB_TRI_ARGS);
}

kernel void heun_predict(global const real4* u, global const real4* v, global real4* u_pred,
                         global real4* v_pred, VB_LATTICE_PARAMS, VB_INDENTER_PARAMS, real dt,
                         uint n VB_TRI_PARAMS) {
  explicit_stage(u, v, u_pred, v_pred, VB_LATTICE_ARGS, VB_INDENTER_ARGS, dt, n, 0 VB_TRI_ARGS);
}

kernel void heun_correct(global real4* u, global real4* v, global const real4* u_pred,
                         global const real4* v_pred, VB_LATTICE_PARAMS, VB_INDENTER_PARAMS,
                         real dt, uint n VB_TRI_PARAMS) {
  const uint e = get_global_id(0);
  if (e >= n) return;
  real4 ui = u[e];
  if (ui.w == 0) return;
  const real4 vi = v[e], up = u_pred[e], vp = v_pred[e];
  torus_grip grip = {0};
  real4 a = acceleration(e, up, vp, u_pred, v_pred, VB_LATTICE_ARGS, indenters, t_force, &grip VB_TRI_ARGS);
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
