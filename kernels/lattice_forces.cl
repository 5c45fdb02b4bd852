// Linear lattice springs with optional Kelvin-Voigt dashpots, gathered per element (no atomics:
// every element sums the forces its own connections exert on it, so results are deterministic).
//
// A connection's stiffness is k = κ_d · h · E_ij, where κ_d is the direction class's coefficient
// (docs/PHYSICS.md) and E_ij = 2·E_i·E_j/(E_i+E_j) joins the two halves in series.

// u: displacement (m) with w = inverse mass (1/kg, 0 = held); v: velocity (m/s).
real4 lattice_force(uint e, real4 ui, real4 vi, global const real4* u, global const real4* v,
                    global const real* E, global const uint* cell_of, global const int* grid,
                    int sy, int sz, real h, real dashpot_ratio) {
  const int cell = (int)cell_of[e];
  const real Ei = E[e];
  real4 f = (real4)(0);
#pragma unroll
  for (int d = 0; d < 26; ++d) {
    // Branch-free: a missing neighbour reads the element itself and is masked out, so CPU
    // compilers can vectorise across work-items.
    const int jn = grid[cell + VB_DIR[d][0] + sy * VB_DIR[d][1] + sz * VB_DIR[d][2]];
    const real present = jn >= 0 ? (real)1 : (real)0;
    const int j = jn >= 0 ? jn : (int)e;
    const real4 uj = u[j];
    const real4 r = (real4)(h * VB_DIR[d][0] + (uj.x - ui.x), h * VB_DIR[d][1] + (uj.y - ui.y),
                            h * VB_DIR[d][2] + (uj.z - ui.z), 0);
    const real len_sq = dot3(r, r);
#if VB_RSQRT
    const real inv_len = rsqrt(len_sq);  // a hardware instruction on GPUs
#else
    const real inv_len = 1 / sqrt(len_sq);  // PoCL's rsqrt() is a slow library call (3× here)
#endif
    const real4 n = r * inv_len;
    const real Ej = E[j];
    const real k = present * VB_KAPPA[d] * h * (2 * Ei * Ej / (Ei + Ej));
    real magnitude = k * (len_sq * inv_len - h * VB_DIR_LEN[d]);
#if VB_DASHPOT
    const real reduced_mass = 1 / (ui.w + uj.w);
    magnitude += 2 * dashpot_ratio * sqrt(k * reduced_mass) * dot3(v[j] - vi, n);
#endif
    f += magnitude * n;
  }
  return f;
}

// Net force on a free element from the lattice and gravity (N), before contact constraints.
inline real4 static_force(uint e, real4 ui, real4 vi, global const real4* u, global const real4* v,
                          global const real* E, global const uint* cell_of, global const int* grid,
                          int sy, int sz, real h, real dashpot_ratio, real4 gravity) {
  real4 f = lattice_force(e, ui, vi, u, v, E, cell_of, grid, sy, sz, h, dashpot_ratio);
#if VB_GRAVITY
  f += xyz0(gravity) / ui.w;
#endif
  return f;
}

#if VB_INDENTER
// Signed distance from the indenter surface (m, < 0 inside) and the outward contact normal.
inline real indenter_distance(real4 x, real4 position, real4 normal, real radius, real4* n_out) {
  if (radius < 0) {  // plate
    *n_out = normal;
    return dot3(x - position, normal);
  }
  const real4 d = xyz0(x - position);
  const real dist = length(d);
  *n_out = dist > 0 ? d / dist : (real4)(0, 0, 1, 0);
  return dist - radius;
}

// Frictionless unilateral contact: a touching element cannot be pushed into the indenter, so the
// inward normal part of its force is carried by the indenter. Returns that part (force on the
// indenter, N) and removes it from f.
inline real4 contact_constrain(real4* f, real4 x, real4 position, real4 normal, real radius,
                               real h) {
  real4 n;
  const real dist = indenter_distance(x, position, normal, radius, &n);
  const real fn = dot3(*f, n);
  if (dist > REAL_CONTACT_TOL * h || fn >= 0) return (real4)(0);
  *f -= fn * n;
  return fn * n;
}

// Moves an element that ended inside the indenter back onto its surface; its normal velocity
// becomes at least the indenter's.
inline void contact_project(real4* ui, real4* vi, real4 X, real4 position, real4 normal,
                            real radius, real4 velocity) {
  real4 n;
  const real dist = indenter_distance(X + xyz0(*ui), position, normal, radius, &n);
  if (dist >= 0) return;
  *ui -= dist * n;
  const real vn = dot3(*vi, n), wn = dot3(velocity, n);
  if (vn < wn) *vi += (wn - vn) * n;
}
#endif

// Test entry point: lattice forces only (N), for comparison with the host reference.
kernel void lattice_forces(global const real4* u, global const real4* v, global const real* E,
                           global const uint* cell_of, global const int* grid, int sy, int sz,
                           real h, real dashpot_ratio, global real4* f_out, uint n) {
  const uint e = get_global_id(0);
  if (e >= n) return;
  f_out[e] = lattice_force(e, u[e], v[e], u, v, E, cell_of, grid, sy, sz, h, dashpot_ratio);
}
