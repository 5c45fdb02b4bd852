// State check, run every `check_every` steps (never every step): per work-group reductions the
// host finishes. Slots of `partial` per group (VB_CHECK_SLOTS reals):
//   0 max residual force |F| on free elements (N)   1 max speed (m/s; +inf if non-finite)
//   2 kinetic energy (J)                            3 max |u| (m)
//   4..6 force of the tissue on the indenter (N)    7 elements in contact
//   8 non-finite elements
// `partial_arg` holds, per group, the element with the largest speed (first non-finite wins).
#define VB_CHECK_SLOTS 9

kernel __attribute__((reqd_work_group_size(VB_CHECK_WG, 1, 1)))
void check_state(global const real4* u, global const real4* v, VB_LATTICE_PARAMS,
                 VB_INDENTER_PARAMS, global real* partial, global int* partial_arg, uint n) {
  local real s_res[VB_CHECK_WG], s_speed[VB_CHECK_WG], s_ke[VB_CHECK_WG], s_disp[VB_CHECK_WG];
  local real s_rx[VB_CHECK_WG], s_ry[VB_CHECK_WG], s_rz[VB_CHECK_WG], s_contact[VB_CHECK_WG];
  local real s_bad[VB_CHECK_WG];
  local int s_arg[VB_CHECK_WG];
  const uint e = get_global_id(0), l = get_local_id(0);

  real res = 0, speed = 0, ke = 0, disp = 0, contact = 0, bad = 0;
  real4 reaction = (real4)(0);
  if (e < n) {
    const real4 ui = u[e], vi = v[e];
    const int finite = isfinite(ui.x) && isfinite(ui.y) && isfinite(ui.z) && isfinite(vi.x) &&
                       isfinite(vi.y) && isfinite(vi.z);
    speed = finite ? length(xyz0(vi)) : (real)INFINITY;
    bad = finite ? 0 : 1;
    disp = finite ? length(xyz0(ui)) : 0;
    if (finite && ui.w != 0) {
      real4 f = static_force(e, ui, vi, u, v, VB_LATTICE_ARGS);
#if VB_INDENTER
      const real4 x = rest_position(cell_of[e], sy, sz, origin, h) + xyz0(ui);
      reaction = contact_constrain(&f, x, ind_force_pos, ind_normal, ind_radius, h);
      contact = dot3(reaction, reaction) > 0 ? 1 : 0;
#endif
      res = length(xyz0(f));
      ke = (real)0.5 * dot3(vi, vi) / ui.w;
    }
  }
  s_res[l] = res; s_speed[l] = speed; s_ke[l] = ke; s_disp[l] = disp;
  s_rx[l] = reaction.x; s_ry[l] = reaction.y; s_rz[l] = reaction.z;
  s_contact[l] = contact; s_bad[l] = bad; s_arg[l] = (int)e;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint stride = VB_CHECK_WG / 2; stride > 0; stride /= 2) {
    if (l < stride) {
      const uint o = l + stride;
      s_res[l] = fmax(s_res[l], s_res[o]);
      if (s_speed[o] > s_speed[l]) { s_speed[l] = s_speed[o]; s_arg[l] = s_arg[o]; }
      s_ke[l] += s_ke[o];
      s_disp[l] = fmax(s_disp[l], s_disp[o]);
      s_rx[l] += s_rx[o]; s_ry[l] += s_ry[o]; s_rz[l] += s_rz[o];
      s_contact[l] += s_contact[o];
      s_bad[l] += s_bad[o];
    }
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (l == 0) {
    global real* p = partial + get_group_id(0) * VB_CHECK_SLOTS;
    p[0] = s_res[0]; p[1] = s_speed[0]; p[2] = s_ke[0]; p[3] = s_disp[0];
    p[4] = s_rx[0]; p[5] = s_ry[0]; p[6] = s_rz[0]; p[7] = s_contact[0]; p[8] = s_bad[0];
    partial_arg[get_group_id(0)] = s_arg[0];
  }
}
