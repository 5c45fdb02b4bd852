// Dynamic relaxation (solver.integrator = "relaxation"; docs/PHYSICS.md, "Fast equilibrium"):
// symplectic Euler on fictitious dynamics that share the static equilibrium of the real model,
//   m̃_e·v' = f_static(u) − c·m̃_e·v,   u' = u + dt·v'.
// m̃_e = m_e / relax_scale[e]: every element's mass is scaled so that its own Gershgorin bound on
// the highest frequency equals the model's (the stiffest element keeps its mass), so soft tissue
// next to stiff skin no longer waits for the step the skin sets. c is the host's estimate of
// critical damping of the lowest mode (the Rayleigh quotient the check kernel sums), updated at
// each check. Gravity still uses the real mass (u.w), so the equilibrium is the real one.
// With the volume constraint (VB_VOLUME_LAG) the step feels the constraint's lagged pressure, as
// Heun's predicted stage does (kernels/integrate.cl, less_lag), and the projection after it,
// weighted by the same fictitious masses, only corrects what that misses (kernels/volume.cl,
// lag_update: M ← M + μ, so at equilibrium M = dt·p).
// With the projection alone the fixed point was no equilibrium of the constrained problem (each
// step pushes the surface off the constraint by dt²·p·g/m̃, the projection moves it back by the
// real masses, along the gradient where the step left it): the residual stalled at ~1e-3·F_ref
// (test RelaxationColumn.WithTheVolumeConstraintReachesTheDampedEquilibrium).
kernel void relax_step(VB_STEP_STATE_PARAMS, VB_LATTICE_KERNEL_PARAMS, VB_INDENTER_AT_PARAMS, real dt,
                       uint n, global const real* relax_scale, real c VB_LAG_KERNEL_PARAMS VB_TRI_PARAMS VB_STATE_PARAM) {
  VB_UNPACK_LATTICE;
  VB_UNPACK_STEP_STATE(const, );
  const uint e = VB_STEP_INDEX(get_global_id(0));
  if (e >= VB_STEP_N) return;
  real4 ui = u[e], vi = v[e];
  const real4 u_start = ui;
  if (ui.w != 0) {
    // acceleration() is f/m with the indenters' constraint (no global damping is compiled in);
    // m/m̃ turns it into f/m̃, then the fictitious damping.
    torus_grip grip = {0};  // on the acceleration, as in integrate.cl (the indenters' scaled here)
    const real4 f = less_lag(lattice_force(e, ui, vi, u, v, VB_LATTICE_ARGS), e, VB_LAG_KERNEL_ARGS);
    // The step ends at u + dt·v + dt²·a; the indenters see f/m, hence their gain carries the scale.
    const real scale = relax_scale[e];
    real4 a = acceleration_from(f, e, ui, vi, VB_LATTICE_ARGS, indenters, t_force, dt, dt * dt * scale,
                                &grip VB_TRI_ARGS) * scale - c * xyz0(vi);
    grip.grip_n *= scale;
#if VB_TORI
    torus_constrain_all(&a, rest_position(cell_of[e], sy, sz, origin, h) + xyz0(ui), vi, dt, dt * dt, indenters, t_force,
                        h, &grip);
#endif
    vi = xyz0(vi + dt * a);
    torus_apply_grip(&vi, grip, dt);
    ui += dt * vi;
    finish_stage(e, &ui, &vi, u_start, cell_of, sy, sz, origin, h, indenters, t_force, t_project);
  }
  u_out[e] = ui;
  v_out[e] = vi;
}

#if VB_LANES
// relax_step for CPUs, 8 free elements per work-item (kernels/integrate_lanes.cl: why, which
// scenes, and free_list): the same operations in the same order.
kernel void relax_step_lanes(VB_STEP_STATE_PARAMS, VB_LATTICE_KERNEL_PARAMS, VB_INDENTER_AT_PARAMS, real dt,
                             uint n_free, global const real* relax_scale, real c,
                             global const uint* free_list VB_LAG_KERNEL_PARAMS VB_STATE_PARAM) {
  lanes_explicit_stage(VB_STEP_STATE_POINTERS, VB_LATTICE_KERNEL_ARGS, dt, n_free, free_list, 1, 1, relax_scale, c,
                       VB_LAG_KERNEL_ARGS);
}
#endif
