// Linear lattice springs with optional Kelvin-Voigt dashpots, gathered per element (no atomics:
// every element sums the forces its own connections exert on it, so results are deterministic).
//
// A connection's stiffness is k = κ_d · h · E_ij, where κ_d is the direction class's coefficient
// (docs/PHYSICS.md) and E_ij = 2·E_i·E_j/(E_i+E_j) joins the two halves in series.

// Force on element e from its connections (N). Linear-spring tissues: springs k = κ_d·h·E_ij.
// Hyperelastic tissues (VB_HYPER): the element stresses of pass 1 (Q·h·d from each neighbour,
// Q_e·Σh·d from the element itself) plus hourglass control. Per connection, each end adds half a
// spring: a linear end ½k(|r| − L), a hyperelastic end c_hg·k(|r| − |F·h·d|), whose rest length is
// the length its own affine fit predicts, so affine fields feel no hourglass force.
// u: displacement (m) with w = inverse mass (1/kg, 0 = held); v: velocity (m/s).
real4 lattice_force(uint e, real4 ui, real4 vi, global const real4* u, global const real4* v, VB_LATTICE_PARAMS) {
  const int cell = (int)cell_of[e];
  const real Ei = E[e];
  real4 f = (real4)(0);
#if VB_HYPER
  const int law_i = (int)materials[VB_MAT_STRIDE * tissue_of[e]];
  const mat3 Fi = mat3_load(Fs, e);
  real4 own_offsets = (real4)(0);
#endif
#pragma unroll
  for (int d = 0; d < 26; ++d) {
    // Branch-free: a missing neighbour reads the element itself and is masked out, so CPU
    // compilers can vectorise across work-items.
    const int jn = grid[cell + VB_DIR[d][0] + sy * VB_DIR[d][1] + sz * VB_DIR[d][2]];
    const real present = jn >= 0 ? (real)1 : (real)0;
    const int j = jn >= 0 ? jn : (int)e;
    const real4 uj = u[j];
    const real4 hd = (real4)(h * VB_DIR[d][0], h * VB_DIR[d][1], h * VB_DIR[d][2], 0);
    const real4 r = (real4)(hd.x + (uj.x - ui.x), hd.y + (uj.y - ui.y), hd.z + (uj.z - ui.z), 0);
    const real len_sq = dot3(r, r);
#if VB_RSQRT
    const real inv_len = rsqrt(len_sq);  // a hardware instruction on GPUs
#else
    const real inv_len = 1 / sqrt(len_sq);  // PoCL's rsqrt() is a slow library call (3× here)
#endif
    const real len = len_sq * inv_len;
    const real4 n = r * inv_len;
    const real Ej = E[j];
    const real k = present * VB_KAPPA[d] * h * (2 * Ei * Ej / (Ei + Ej));
    const real rest = h * VB_DIR_LEN[d];
#if VB_HYPER
    const int law_j = (int)materials[VB_MAT_STRIDE * tissue_of[j]];
    real magnitude = law_i == 0 ? (real)0.5 * k * (len - rest) : hourglass * k * (len - length(mat3_apply(Fi, hd)));
    magnitude += law_j == 0 ? (real)0.5 * k * (len - rest)
                            : hourglass * k * (len - length(mat3_apply(mat3_load(Fs, (uint)j), hd)));
    if (law_j != 0) f += present * mat3_apply(mat3_load(Qs, (uint)j), hd);
    own_offsets += present * hd;
#else
    real magnitude = k * (len - rest);
#endif
#if VB_DASHPOT
    const real reduced_mass = 1 / (ui.w + uj.w);
    magnitude += 2 * dashpot_ratio * sqrt(k * reduced_mass) * dot3(v[j] - vi, n);
#endif
    f += magnitude * n;
  }
#if VB_HYPER
  if (law_i != 0) f += mat3_apply(mat3_load(Qs, e), own_offsets);
#endif
  return f;
}

// Net force on a free element from the lattice and gravity (N), before contact constraints.
inline real4 static_force(uint e, real4 ui, real4 vi, global const real4* u, global const real4* v,
                          VB_LATTICE_PARAMS) {
  real4 f = lattice_force(e, ui, vi, u, v, VB_LATTICE_ARGS);
#if VB_GRAVITY
  f += xyz0(gravity) / ui.w;
#endif
  return f;
}

#if VB_INDENTERS
inline real4 indenter_position(global const real* ind, real t) {
  const real tt = fmin(t, ind[12]);
  return (real4)(ind[0] + ind[8] * tt, ind[1] + ind[9] * tt, ind[2] + ind[10] * tt, 0);
}

inline real4 indenter_velocity(global const real* ind, real t) {
  return t < ind[12] ? (real4)(ind[8], ind[9], ind[10], 0) : (real4)(0);
}

// Signed distance from the indenter surface at time t (m, < 0 inside) and the outward normal.
inline real indenter_distance(real4 x, global const real* ind, real t, real4* n_out) {
  const real4 p = indenter_position(ind, t);
  if (ind[3] < 0) {  // plate
    *n_out = (real4)(ind[4], ind[5], ind[6], 0);
    return dot3(x - p, *n_out);
  }
  const real4 d = xyz0(x - p);
  const real dist = length(d);
  *n_out = dist > 0 ? d / dist : (real4)(0, 0, 1, 0);
  return dist - ind[3];
}

// Frictionless unilateral contact: a touching element cannot be pushed into the indenter, so the
// inward normal part of its force is carried by the indenter. Returns that part (force on the
// indenter, N) and removes it from f.
inline real4 contact_constrain(real4* f, real4 x, global const real* ind, real t, real h) {
  real4 n;
  const real dist = indenter_distance(x, ind, t, &n);
  const real fn = dot3(*f, n);
  if (dist > REAL_CONTACT_TOL * h || fn >= 0) return (real4)(0);
  *f -= fn * n;
  return fn * n;
}

inline void contact_constrain_all(real4* f, real4 x, global const real* indenters, real t, real h) {
  for (int i = 0; i < VB_INDENTERS; ++i) contact_constrain(f, x, indenters + VB_IND_STRIDE * i, t, h);
}

// Moves an element that ended inside an indenter back onto its surface; its normal velocity
// becomes at least the indenter's.
inline void contact_project_all(real4* ui, real4* vi, real4 X, global const real* indenters, real t) {
  for (int i = 0; i < VB_INDENTERS; ++i) {
    global const real* ind = indenters + VB_IND_STRIDE * i;
    real4 n;
    const real dist = indenter_distance(X + xyz0(*ui), ind, t, &n);
    if (dist >= 0) continue;
    *ui -= dist * n;
    const real vn = dot3(*vi, n), wn = dot3(indenter_velocity(ind, t), n);
    if (vn < wn) *vi += (wn - vn) * n;
  }
}
#endif

// Test entry point: lattice forces only (N), for comparison with the host reference.
kernel void lattice_forces(global const real4* u, global const real4* v, VB_LATTICE_PARAMS, global real4* f_out,
                           uint n) {
  const uint e = get_global_id(0);
  if (e >= n) return;
  f_out[e] = lattice_force(e, u[e], v[e], u, v, VB_LATTICE_ARGS);
}
