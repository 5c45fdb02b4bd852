// State check, run every `check_every` steps (never every step): per work-group reductions the
// host finishes. Slots of `partial` per group (VB_CHECK_SLOTS = 5 + 4·VB_INDENTERS reals):
//   0 max residual force |F| on free elements (N)   1 max speed (m/s; +inf if non-finite)
//   2 kinetic energy (J)                            3 max |u| (m)
//   4 non-finite elements
//   5 + 4i .. 7 + 4i  force of the tissue on indenter i (N), 8 + 4i  its contact elements
// With VB_RELAX (dynamic relaxation, kernels/relax.cl) four more sums follow: Rayleigh quotients,
// each ≥ the lowest mode's ω², that the host sets the damping from (Underwood). One is of the
// displacement u (the lattice force is zero at rest), one of the change Δu since the previous
// check (stored in relax_prev with the lattice force then), which late in a relaxation is the
// slowest mode itself. With R = 5 + 4·VB_INDENTERS:
//   R     uᵀKu = −Σ u·f_lattice(u)          R + 1  uᵀM̃u = Σ m̃|u|²
//   R + 2 ΔuᵀKΔu = −Σ Δu·Δf_lattice         R + 3  ΔuᵀM̃Δu = Σ m̃|Δu|²
// (J and kg·m²; exact for linear springs, secant/tangent-like for the other laws).
#define VB_SLOT_SUM(s) ((s) == 2 || (s) >= 4)

kernel __attribute__((reqd_work_group_size(VB_CHECK_WG, 1, 1)))
void check_state(global const real4* u, global const real4* v, VB_LATTICE_PARAMS,
                 VB_INDENTER_PARAMS, global real* partial, global int* partial_arg, uint n
#if VB_VOLUME
                 , global const real4* volume_grad, global const real* volume_scalars
#endif
#if VB_RELAX
                 , global const real* relax_scale, global real4* relax_prev
#endif
                 ) {
  local real s[VB_CHECK_SLOTS][VB_CHECK_WG];
  local int s_arg[VB_CHECK_WG];
  const uint e = get_global_id(0), l = get_local_id(0);

  real value[VB_CHECK_SLOTS];
  for (int k = 0; k < VB_CHECK_SLOTS; ++k) value[k] = 0;
  if (e < n) {
    const real4 ui = u[e], vi = v[e];
    const int finite = isfinite(ui.x) && isfinite(ui.y) && isfinite(ui.z) && isfinite(vi.x) &&
                       isfinite(vi.y) && isfinite(vi.z);
    value[1] = finite ? length(xyz0(vi)) : (real)INFINITY;
    value[3] = finite ? length(xyz0(ui)) : 0;
    value[4] = finite ? 0 : 1;
    if (finite && ui.w != 0) {
      real4 f = static_force(e, ui, vi, u, v, VB_LATTICE_ARGS);
#if VB_RELAX
      const int R = 5 + 4 * VB_INDENTERS;
#if VB_GRAVITY
      const real4 f_lattice = xyz0(f - xyz0(gravity) / ui.w);
#else
      const real4 f_lattice = xyz0(f);
#endif
      const real4 du = xyz0(ui) - relax_prev[2 * e];
      const real scaled_mass = 1 / (ui.w * relax_scale[e]);
      value[R] = -dot3(ui, f_lattice);
      value[R + 1] = dot3(ui, ui) * scaled_mass;
      value[R + 2] = -dot3(du, f_lattice - relax_prev[2 * e + 1]);
      value[R + 3] = dot3(du, du) * scaled_mass;
      relax_prev[2 * e] = xyz0(ui);
      relax_prev[2 * e + 1] = f_lattice;
#endif
#if VB_VOLUME
      f -= volume_scalars[3] * volume_grad[e];
#endif
#if VB_INDENTERS
      const real4 x = rest_position(cell_of[e], sy, sz, origin, h) + xyz0(ui);
      for (int i = 0; i < VB_INDENTERS; ++i) {
        const real4 reaction = contact_constrain(&f, x, indenters + VB_IND_STRIDE * i, t_force, h);
        value[5 + 4 * i] = reaction.x;
        value[6 + 4 * i] = reaction.y;
        value[7 + 4 * i] = reaction.z;
        value[8 + 4 * i] = dot3(reaction, reaction) > 0 ? 1 : 0;
      }
#endif
      value[0] = length(xyz0(f));
      value[2] = (real)0.5 * dot3(vi, vi) / ui.w;
    }
  }
  for (int k = 0; k < VB_CHECK_SLOTS; ++k) s[k][l] = value[k];
  s_arg[l] = (int)e;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint stride = VB_CHECK_WG / 2; stride > 0; stride /= 2) {
    if (l < stride) {
      const uint o = l + stride;
      if (s[1][o] > s[1][l]) s_arg[l] = s_arg[o];
      for (int k = 0; k < VB_CHECK_SLOTS; ++k) s[k][l] = VB_SLOT_SUM(k) ? s[k][l] + s[k][o] : fmax(s[k][l], s[k][o]);
    }
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (l == 0) {
    for (int k = 0; k < VB_CHECK_SLOTS; ++k) partial[get_group_id(0) * VB_CHECK_SLOTS + k] = s[k][0];
    partial_arg[get_group_id(0)] = s_arg[0];
  }
}
