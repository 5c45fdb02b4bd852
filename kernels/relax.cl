// Dynamic relaxation (solver.integrator = "relaxation"; docs/PHYSICS.md, "Fast equilibrium"):
// symplectic Euler on fictitious dynamics that share the static equilibrium of the real model,
//   m̃_e·v' = f_static(u) − c·m̃_e·v,   u' = u + dt·v'.
// m̃_e = m_e / relax_scale[e]: every element's mass is scaled so that its own Gershgorin bound on
// the highest frequency equals the model's (the stiffest element keeps its mass), so soft tissue
// next to stiff skin no longer waits for the step the skin sets. c is the host's estimate of
// critical damping of the lowest mode (the Rayleigh quotient the check kernel sums), updated at
// each check. Gravity still uses the real mass (u.w), so the equilibrium is the real one.
kernel void relax_step(global const real4* u, global const real4* v, global real4* u_out,
                       global real4* v_out, VB_LATTICE_PARAMS, VB_INDENTER_PARAMS, real dt,
                       uint n, global const real* relax_scale, real c) {
  const uint e = get_global_id(0);
  if (e >= n) return;
  real4 ui = u[e], vi = v[e];
  if (ui.w != 0) {
    const real inverse_mass = ui.w * relax_scale[e];  // 1/m̃
    real4 f = static_force(e, ui, vi, u, v, VB_LATTICE_ARGS) - c * xyz0(vi) / inverse_mass;
#if VB_INDENTERS || VB_TORI
    const real4 X = rest_position(cell_of[e], sy, sz, origin, h);
#endif
#if VB_INDENTERS
    contact_constrain_all(&f, X + xyz0(ui), indenters, t_force, h);
#endif
    real4 a = inverse_mass * f;
#if VB_TORI
    torus_grip grip = {0};  // on the acceleration, as in integrate.cl
    torus_constrain_all(&a, X + xyz0(ui), indenters, t_force, h, &grip);
#endif
    vi = xyz0(vi + dt * a);
#if VB_TORI
    torus_apply_grip(&vi, grip, dt);
#endif
    ui += dt * vi;
    finish_stage(e, &ui, &vi, cell_of, sy, sz, origin, h, indenters, t_project);
#if VB_TORI
    torus_project_all(&ui, &vi, X, indenters, t_project, h);
#endif
  }
  u_out[e] = ui;
  v_out[e] = vi;
}
