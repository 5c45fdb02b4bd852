// State check, run every `check_every` steps (never every step): per work-group reductions the
// host finishes. Slots of `partial` per group (VB_CHECK_SLOTS = 6 + 4·VB_INDENTERS + 8·VB_TORI
// + 4·VB_RELAX reals):
//   0 max residual ratio |F|/(E·h²) on free elements  1 max speed (m/s; +inf if non-finite)
//   2 kinetic energy (J)                               3 max |u| (m)
//   4 non-finite elements                              5 max speed ratio |v|/√(E/ρ)
//   6 + 4i .. 8 + 4i  force of the tissue on indenter i (N), 9 + 4i  its contact elements
// The ratios scale each element by its own modulus, or a stiffer hyperelastic neighbour's
// (check_scale: 1/(E·h²), 1/√(E/ρ) per element), so the equilibrium test holds for every tissue,
// not only for the stiffest (docs/SCENE.md, "Equilibrium criterion").
// `partial_arg` holds, per group, the element with the largest speed (first non-finite wins).
// With VB_VOLUME the residual is that of the constrained problem: the pressure term p·g
// (kernels/volume.cl, computed just before) is taken off the static force of surface elements.
// With VB_TORI, 8 slots per torus follow from VB_TORUS_SLOT0: 0–2 force of the tissue on it (N),
// 3 contact elements, 4 their contact area (m², per-element shares), 5 the sum of their normal
// forces |f_n| (N), 6 peak contact pressure (Pa, max), 7 deepest penetration of a free element
// into the tube (m, max).
// With VB_TRI_CONTACT a triangle-contact indenter's slots hold minus the forces it exerts through
// the surface triangles (kernels/triangle_contact.cl), with friction plus the tangential force
// its friction carries, and its count of elements that carry some.
// With VB_RELAX (dynamic relaxation, kernels/relax.cl) four more sums follow: Rayleigh quotients,
// each ≥ the lowest mode's ω², that the host sets the damping from (Underwood). One is of the
// displacement u from rest (the lattice force is zero there), one of the change Δu since the previous
// check (stored in relax_prev with the lattice force then), which late in a relaxation is the
// slowest mode itself. With R = VB_RELAX_SLOT0 (after the tori's slots):
//   R     uᵀKu = −Σ u·f_lattice(u)          R + 1  uᵀM̃u = Σ m̃|u|²
//   R + 2 ΔuᵀKΔu = −Σ Δu·Δf_lattice         R + 3  ΔuᵀM̃Δu = Σ m̃|Δu|²
// (J and kg·m²; exact for linear springs, secant/tangent-like for the other laws).
#define VB_IND_SLOT0 6
#define VB_TORUS_SLOT0 (VB_IND_SLOT0 + 4 * VB_INDENTERS)
#define VB_TORUS_SLOTS 8
#define VB_RELAX_SLOT0 (VB_TORUS_SLOT0 + VB_TORUS_SLOTS * VB_TORI)
#if VB_TORI
#define VB_SLOT_SUM(s) ((s) == 2 || (s) == 4 || ((s) > 5 && ((s) < VB_TORUS_SLOT0 || (s) >= VB_RELAX_SLOT0 || \
                                                  ((s) - VB_TORUS_SLOT0) % VB_TORUS_SLOTS < 6)))
#else
#define VB_SLOT_SUM(s) ((s) == 2 || (s) == 4 || (s) > 5)
#endif

#if VB_TORI
// Contact of element x with torus i at the check: the carried force (normal and, with friction,
// the tangential part up to μ·|f_n|) is removed from f; fills the torus's slots.
VB_INLINE void torus_check(real4* f, real4 x, global const real* table, int i, real t, real h, real area,
                        real* value) {
  global const real* tor = torus_row(table, i);
  real4 n, w;
  const real dist = torus_distance(x, table, tor, t, &n, &w);
  torus_grip grip = {0};
  real4 carried = torus_constrain(f, x, (real4)(0), 0, 0, table, tor, t, h, &grip);
  const real fn = -dot3(carried, n);  // compressive normal force (N), ≥ 0
#if VB_FRICTION
  if (fn > 0 && tor[3] > 0) carried += friction_hold(f, n, fn, tor[3]);
#endif
  real* slot = value + VB_TORUS_SLOT0 + VB_TORUS_SLOTS * i;
  slot[0] = carried.x;
  slot[1] = carried.y;
  slot[2] = carried.z;
  slot[3] = fn > 0 ? 1 : 0;
  slot[4] = fn > 0 ? area : 0;
  slot[5] = fn;
  slot[6] = fn > 0 ? fn / area : 0;
  slot[7] = fmax(-dist, (real)0);
}
#endif

kernel __attribute__((reqd_work_group_size(VB_CHECK_WG, 1, 1)))
void check_state(global const real4* u, global const real4* v, VB_LATTICE_KERNEL_PARAMS,
                 VB_INDENTER_PARAMS, global real* partial, global int* partial_arg, uint n,
                 global const real2* check_scale  // per element: 1/(E·h²) (1/N), 1/√(E/ρ) (s/m)
#if VB_VOLUME
                 , global const real4* volume_grad, global const real* volume_scalars
#endif
#if VB_TORI
                 , global const real* contact_area  // per element: its share of the surface (m²)
#endif
#if VB_RELAX
                 , global const real* relax_scale, global real4* relax_prev
#endif
#if VB_FRICTION
                 , real friction_dt  // the steps' dt (s): sets the slip speed an indenter's friction tells
#endif
                 VB_TRI_PARAMS) {
  VB_UNPACK_LATTICE;
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
#if VB_FRICTION
      // An element in contact slides if its tangential speed relative to the indenter is above a
      // hundredth of what one step's friction removes (μ·fn·dt/m, per unit μ·fn here; the grip
      // leaves zero, to rounding, on an element it stopped).
#if VB_RELAX
      const real slip_per_n = (real)0.01 * ui.w * relax_scale[e] * friction_dt;
#else
      const real slip_per_n = (real)0.01 * ui.w * friction_dt;
#endif
#endif
#if VB_RELAX
      const int R = VB_RELAX_SLOT0;
#if VB_GRAVITY
      const real4 f_lattice = xyz0(f - xyz0(gravity) / ui.w);
#else
      const real4 f_lattice = xyz0(f);
#endif
      const real4 du = xyz0(ui) - relax_prev[2 * e];
      const real scaled_mass = 1 / (ui.w * relax_scale[e]);
#if VB_REST_OFFSET
      const real4 from_rest = xyz0(ui - rest_offset[e]);  // the lattice force is zero there
#else
      const real4 from_rest = xyz0(ui);
#endif
      value[R] = -dot3(from_rest, f_lattice);
      value[R + 1] = dot3(from_rest, from_rest) * scaled_mass;
      value[R + 2] = -dot3(du, f_lattice - relax_prev[2 * e + 1]);
      value[R + 3] = dot3(du, du) * scaled_mass;
      relax_prev[2 * e] = xyz0(ui);
      relax_prev[2 * e + 1] = f_lattice;
#endif
#if VB_VOLUME
      f -= volume_scalars[3] * volume_grad[e];
#endif
#if VB_TRI_CONTACT
      // Triangle contact: the element's share of the penalty forces is part of its force; the
      // indenter feels the opposite (the sum over elements is minus the sum of triangle forces).
      for (int i = 0; i < VB_INDENTERS; ++i) {
        if (!uses_triangles(indenters + VB_IND_STRIDE * i)) continue;
        const real4 pushed = triangle_contact_force(e, i, corner_force, tri_start, tri_corner, n_tri);
        f += pushed;
        real4 reaction = -pushed;
#if VB_FRICTION
        // Friction (normal pushed/|pushed|): kinetic μ·|pushed| along a sliding element's slip, the
        // tangential rest of the force of one at rest up to μ·|pushed|; the indenter feels it too.
        global const real* ind = indenters + VB_IND_STRIDE * i;
        const real fn = length(pushed), mu = ind[17];
        if (fn > 0 && mu > 0)
          reaction += friction_carried(&f, pushed / fn, fn, mu, vi - indenter_velocity(ind, t_force), slip_per_n * mu * fn);
#endif
        value[VB_IND_SLOT0 + 4 * i] = reaction.x;
        value[VB_IND_SLOT0 + 1 + 4 * i] = reaction.y;
        value[VB_IND_SLOT0 + 2 + 4 * i] = reaction.z;
        value[VB_IND_SLOT0 + 3 + 4 * i] = dot3(pushed, pushed) > 0 ? 1 : 0;
      }
#endif
#if VB_INDENTERS
      const real4 x = rest_position(cell_of[e], sy, sz, origin, h) + xyz0(ui);
      for (int i = 0; i < VB_INDENTERS; ++i) {
#if VB_TRI_CONTACT
        if (uses_triangles(indenters + VB_IND_STRIDE * i)) continue;
#endif
        torus_grip grip = {0};
        real4 reaction = contact_constrain(&f, x, (real4)(0), 0, 0, indenters + VB_IND_STRIDE * i, t_force, h, &grip);
#if VB_FRICTION
        // Friction: kinetic μ·|f_n| for a sliding element, up to μ·|f_n| for one at rest (grip_n = μ·|f_n|).
        if (grip.grip_n > 0)
          reaction += friction_carried(&f, grip.normal, length(xyz0(reaction)), indenters[VB_IND_STRIDE * i + 17],
                                       vi - grip.surface_v, slip_per_n * grip.grip_n);
#endif
        value[VB_IND_SLOT0 + 4 * i] = reaction.x;
        value[VB_IND_SLOT0 + 1 + 4 * i] = reaction.y;
        value[VB_IND_SLOT0 + 2 + 4 * i] = reaction.z;
        value[VB_IND_SLOT0 + 3 + 4 * i] = dot3(reaction, reaction) > 0 ? 1 : 0;
      }
#endif
#if VB_TORI
      {
        const real4 xt = rest_position(cell_of[e], sy, sz, origin, h) + xyz0(ui);
        const real area = contact_area[e] > 0 ? contact_area[e] : h * h;
        for (int i = 0; i < VB_TORI; ++i) torus_check(&f, xt, indenters, i, t_force, h, area, value);
      }
#endif
      const real2 own_scale = check_scale[e];
      value[0] = length(xyz0(f)) * own_scale.x;
      value[2] = (real)0.5 * dot3(vi, vi) / ui.w;
      value[5] = value[1] * own_scale.y;
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
