// Linear lattice springs with optional Kelvin-Voigt dashpots, gathered per element (no atomics:
// every element sums the forces its own connections exert on it, so results are deterministic).
//
// A connection's stiffness is k = κ_d · h · E_ij, where κ_d is the direction class's coefficient
// (docs/PHYSICS.md) and E_ij = 2·E_i·E_j/(E_i+E_j) joins the two halves in series.

#if VB_BIPHASIC
// Biphasic spring (docs/PHYSICS.md, "Biphasic springs"): force over k·L at strain ε,
//   g(ε) = ε + c3·ε³ for |ε| ≤ εc,  sgn(ε)·(εc + c3·εc³ + (1 + 3·c3·εc²)·(|ε| − εc)) beyond.
// With m = min(|ε|, εc) both pieces are one expression (no branch).
inline real biphasic_force_factor(real eps, real c3, real ec) {
  const real a = fabs(eps), m = fmin(a, ec);
  return copysign(m * (1 + c3 * m * m) + (1 + 3 * c3 * m * m) * (a - m), eps);
}

// Half a spring from one end of a connection (N): ½k(|r| − L) for a linear end, ½k·L·g(ε) with
// the end's own tissue's c3 and εc (material table slots 9 and 10) for a biphasic end. Both are
// computed and one selected, so CPU compilers can still vectorise across work-items.
inline real spring_end(int law, global const real* mat, real k, real len, real rest) {
  const real stretch = len - rest;
  const real biphasic = rest * biphasic_force_factor(stretch / rest, mat[9], mat[10]);
  return (real)0.5 * k * (law == VB_LAW_BIPHASIC ? biphasic : stretch);
}
#else
#define spring_end(law, mat, k, len, rest) ((real)0.5 * (k) * ((len) - (rest)))
#endif

// Heun's predicted stage packed (VB_PRED_PACKED; Simulator::pred_packed_): its u array holds
// (ũx, ũy, ũz, ṽx) and its v array's first half (ṽy, ṽz) as real2, so a warp's read of a
// neighbour's state touches 4 + 2 cache lines instead of 4 + 4: the reads cost by the lines they
// touch (H200: heun_correct 10% shorter, the 1.5M cube's step 3-5%, 512k's 7%; docs/
// PERFORMANCE.md, "Packed predicted stage"). The inverse mass is not in it: it stays in the state's u.w (w_of),
// which no stage changes (heun_correct writes each u[e] back with the same w, so a neighbour reads
// the same inverse mass before or after). `packed` is a constant at every call (0: the stage as
// two real4 arrays). Only the host's plain case uses it: one work-item per element, no step list,
// nothing else reading the stage.
#ifndef VB_PRED_PACKED
#define VB_PRED_PACKED 0
#endif
#if VB_PRED_PACKED && (VB_SPLIT > 1 || VB_VOLUME || VB_STEP_LIST || VB_LANES || VB_TRI_CONTACT || VB_PERSISTENT || \
                       VB_INDENTERS || VB_TORI || VB_HYPER || VB_BIPHASIC)
#error "VB_PRED_PACKED: the predicted stage is read as two real4 arrays by this configuration"
#endif
#define VB_STAGE_PARAMS int packed, global const real4 *w_of
VB_INLINE void stage_load(global const real4* u, global const real4* v, uint j, VB_STAGE_PARAMS, real4* uj,
                          real4* vj) {
  if (!packed) {
    *uj = u[j];
    *vj = v[j];
    return;
  }
  const real4 a = u[j];
  const real2 b = ((global const real2*)v)[j];
  *uj = (real4)(a.x, a.y, a.z, w_of[j].w);
  *vj = (real4)(a.w, b.x, b.y, 0);
}
VB_INLINE void stage_store(global real4* u, global real4* v, uint e, int packed, real4 ue, real4 ve) {
  if (!packed) {
    u[e] = ue;
    v[e] = ve;
    return;
  }
  u[e] = (real4)(ue.x, ue.y, ue.z, ve.x);
  ((global real2*)v)[e] = (real2)(ve.y, ve.z);
}

// Linear springs only (no rest offsets): the force on a free element whose present neighbours all
// have its E and inverse mass w, which the host marks with a negative E (engine/sim/
// uniform_neighbourhood.hpp). Then E_ij = E, k = κ_d·h·E and the dashpot's 2ζ·√(k/(2w)) =
// 2ζ·√(h·E/(2w))·√κ_d, one square root per element: no neighbour modulus to load and no
// reciprocal or square root per connection (docs/PERFORMANCE.md, "Uniform-neighbourhood short loop"). The same force as
// lattice_force_pending's, (k(|r| − L) + c·Δv·r̂)·r̂, written as s·r with
// s = k − k·L/|r| + c·(Δv·r)/|r|²: no unit vector, the mask on s alone, h·d's zero components
// never added: 11% fewer instructions per stage and 7% more steps/s on the H200's 1.5M cube
// (docs/PERFORMANCE.md, "Uniform-neighbourhood short loop").
// A coincident neighbour (|r| = 0) has r = 0, so s·r = 0 as in the general loop.
// VB_UNIFORM_PATH (host: GPUs, linear springs, no rest offsets, not in the one-launch step).
#if VB_UNIFORM_PATH
#if VB_DOUBLE
#define VB_LEN_SQ_MIN 1e-300
#else
#define VB_LEN_SQ_MIN 1e-30f
#endif
// h·d's component plus x, with no term where d's component is 0 (d is a constant once unrolled;
// without fast-math h·0 + x is not folded).
#define VB_PLUS_HD(c, x) (VB_DIR[d][c] == 0 ? (x) : VB_DIR[d][c] > 0 ? h + (x) : (x) - h)
VB_INLINE real4 lattice_force_uniform(uint e, real Ei, real4 ui, real4 vi, global const real4* u,
                                      global const real4* v, VB_LATTICE_PARAMS, VB_PENDING_PARAMS, int d_lo, int d_hi,
                                      VB_STAGE_PARAMS) {
  const int cell = (int)cell_of[e];
  const real hE = h * Ei, hhE = h * hE;
#if VB_DASHPOT
  const real damping_e = 2 * dashpot_ratio * sqrt(hE / (2 * ui.w));
#endif
  real4 f = (real4)(0);
#pragma unroll
  for (int d = 0; d < 26; ++d) {
    if (d < d_lo || d >= d_hi) continue;
    const int jn = grid[cell + VB_DIR[d][0] + sy * VB_DIR[d][1] + sz * VB_DIR[d][2]];
    const real present = jn >= 0 ? (real)1 : (real)0;
    const int j = jn >= 0 ? jn : (int)e;
    real4 uj, vj, wgj = (real4)(0);
    stage_load(u, v, (uint)j, packed, w_of, &uj, &vj);
    pending_u(&uj, &wgj, (uint)j, VB_PENDING_ARGS);
    const real4 r = (real4)(VB_PLUS_HD(0, uj.x - ui.x), VB_PLUS_HD(1, uj.y - ui.y), VB_PLUS_HD(2, uj.z - ui.z), 0);
    const real len_sq = dot3(r, r);
#if VB_RSQRT
    const real inv_len = rsqrt(fmax(len_sq, VB_LEN_SQ_MIN));
#else
    const real inv_len = 1 / sqrt(fmax(len_sq, VB_LEN_SQ_MIN));
#endif
    // k − k·L/|r|, κ_d·L_d folded at compile time
    real s = VB_KAPPA[d] * hE - (VB_KAPPA[d] * VB_DIR_LEN[d]) * hhE * inv_len;
#if VB_DASHPOT
    pending_v(&vj, wgj, VB_PENDING_ARGS);
    s += (damping_e * VB_SQRT_KAPPA[d]) * dot3(vj - vi, r) * (inv_len * inv_len);
#endif
    f += (present * s) * r;
  }
  return f;
}
#undef VB_PLUS_HD
#endif

// Force on element e from its connections (N). Linear-spring tissues: springs k = κ_d·h·E_ij.
// Hyperelastic tissues (VB_HYPER): the element stresses of pass 1 (Q·h·d from each neighbour,
// Q_e·Σh·d from the element itself) plus hourglass control. Per connection, each end adds half a
// spring: a linear end ½k(|r| − L), a biphasic end ½k·L·g(ε) (VB_BIPHASIC), a hyperelastic end
// c_hg·k(|r| − |F·r₀|), whose rest length is the length its own affine fit predicts, so affine
// fields feel no hourglass force (r₀ the connection at rest: h·d, or h·d + Δu0 with rest offsets,
// F the element's deformation from rest).
// u: displacement (m) with w = inverse mass (1/kg, 0 = held); v: velocity (m/s). With a pending
// volume projection (VB_PENDING_PARAMS, kernels/common.cl) the neighbours' u, v are read as the
// projection leaves them; ui, vi are the caller's (already projected). Only connections d_lo ≤ d <
// d_hi are summed (kernels/integrate.cl, VB_SPLIT: parts of an element's connections on several
// work-items); 0, 26 for all.
VB_INLINE real4 lattice_force_pending(uint e, real4 ui, real4 vi, global const real4* u, global const real4* v,
                                      VB_LATTICE_PARAMS, VB_PENDING_PARAMS, int d_lo, int d_hi, VB_STAGE_PARAMS) {
#if VB_UNIFORM_PATH
  const real E_marked = E[e];
  if (E_marked < 0) return lattice_force_uniform(e, -E_marked, ui, vi, u, v, VB_LATTICE_ARGS, VB_PENDING_ARGS, d_lo, d_hi,
                                                     packed, w_of);
  const real Ei = E_marked;
#else
  const real Ei = E[e];
#endif
  const int cell = (int)cell_of[e];
  real4 f = (real4)(0);
#if VB_HYPER || VB_BIPHASIC
  global const real* mat_i = materials + VB_MAT_STRIDE * tissue_of[e];
  const int law_i = (int)mat_i[0];
#endif
#if VB_HYPER
  const real4 Ci_diag = (real4)(Qs[3 * e].w, Qs[3 * e + 1].w, Qs[3 * e + 2].w, 0), Ci_off = Cs[e];
  real4 own_offsets = (real4)(0);
#endif
#if VB_REST_OFFSET
  const real4 u0i = rest_offset[e];
#endif
#pragma unroll
  for (int d = 0; d < 26; ++d) {
    if (d < d_lo || d >= d_hi) continue;  // d is a constant once unrolled; the range is uniform
    // Branch-free: a missing neighbour reads the element itself and is masked out, so CPU
    // compilers can vectorise across work-items.
    const int jn = grid[cell + VB_DIR[d][0] + sy * VB_DIR[d][1] + sz * VB_DIR[d][2]];
    const real present = jn >= 0 ? (real)1 : (real)0;
    const int j = jn >= 0 ? jn : (int)e;
    real4 uj, vj, wgj = (real4)(0);
    stage_load(u, v, (uint)j, packed, w_of, &uj, &vj);
    pending_u(&uj, &wgj, (uint)j, VB_PENDING_ARGS);
    const real4 hd = (real4)(h * VB_DIR[d][0], h * VB_DIR[d][1], h * VB_DIR[d][2], 0);
    const real4 r = (real4)(hd.x + (uj.x - ui.x), hd.y + (uj.y - ui.y), hd.z + (uj.z - ui.z), 0);
    const real len_sq = dot3(r, r);
#if VB_RSQRT
    const real inv_len_raw = rsqrt(len_sq);  // a hardware instruction on GPUs
#else
    const real inv_len_raw = 1 / sqrt(len_sq);  // PoCL's rsqrt() is a slow library call (3× here)
#endif
    const real inv_len = len_sq > 0 ? inv_len_raw : (real)0;  // coincident neighbours: no direction, no NaN
    const real len = len_sq * inv_len;
    const real4 n = r * inv_len;
#if VB_UNIFORM_PATH
    const real Ej = fabs(E[j]);  // negative: a uniform neighbourhood (lattice_force_uniform)
#else
    const real Ej = E[j];
#endif
#if VB_DASHPOT
    // One reciprocal serves both k and the dashpot's reduced mass 1/(wi + wj) in 2ζ√(k·m_red):
    // q = 1/((Ei + Ej)(wi + wj)), k = κh·2EiEj·(wi + wj)·q, k·m_red = κh·2EiEj·q.
    const real w_sum = ui.w + uj.w;
    const real kE = present * VB_KAPPA[d] * h * (2 * Ei * Ej);
    const real q = 1 / ((Ei + Ej) * w_sum);
    const real k = kE * w_sum * q;
#else
    const real k = present * VB_KAPPA[d] * h * (2 * Ei * Ej / (Ei + Ej));
#endif
#if VB_REST_OFFSET
    // The connection's rest vector in the unloaded state: h·d plus the change of the two ends'
    // rest offsets (a missing neighbour reads the element itself: h·d, masked out above).
    const real4 r0 = hd + xyz0(rest_offset[j] - u0i);
    const real rest = norm3(r0);
#else
    const real4 r0 = hd;
    const real rest = h * VB_DIR_LEN[d];
#endif
#if VB_BIPHASIC  // biphasic ends need the neighbour's own c3, εc
    global const real* mat_j = materials + VB_MAT_STRIDE * tissue_of[j];
    const int law_j = (int)mat_j[0];
#endif
#if VB_HYPER
    const mat3 Qj = mat3_load(Qs, (uint)j);  // zero for spring tissue
    const real4 Cj_diag = (real4)(Qs[3 * j].w, Qs[3 * j + 1].w, Qs[3 * j + 2].w, 0), Cj_off = Cs[j];
#if VB_BIPHASIC
    const int hyper_j = VB_LAW_HYPER(law_j);
#else
    const int hyper_j = Cj_off.w != 0;  // the neighbour's law without its tissue id and material row
#endif
#if VB_REST_OFFSET
#define VB_STRETCHED(diag, off) stretched_length(diag, off, r0)
#else
#define VB_STRETCHED(diag, off) stretched_length_dir(diag, off, d, h)  // r0 = h·d
#endif
    real magnitude = !VB_LAW_HYPER(law_i) ? spring_end(law_i, mat_i, k, len, rest)
                                          : hourglass * k * (len - VB_STRETCHED(Ci_diag, Ci_off));
    magnitude += !hyper_j ? spring_end(law_j, mat_j, k, len, rest)
                          : hourglass * k * (len - VB_STRETCHED(Cj_diag, Cj_off));
    f += present * mat3_apply_dir(Qj, d, h);
    own_offsets += present * hd;
#elif VB_BIPHASIC
    real magnitude = spring_end(law_i, mat_i, k, len, rest) + spring_end(law_j, mat_j, k, len, rest);
#else
    real magnitude = k * (len - rest);
#endif
#if VB_DASHPOT
    pending_v(&vj, wgj, VB_PENDING_ARGS);
    magnitude += 2 * dashpot_ratio * sqrt(kE * q) * dot3(vj - vi, n);
#endif
    f += magnitude * n;
  }
#if VB_HYPER
  if (VB_LAW_HYPER(law_i)) f += mat3_apply(mat3_load(Qs, e), own_offsets);
  // the dual cells' volumetric energy, once per element (the part of a split force that starts at
  // the first connection); spring elements that are corners of a cell with hyperelastic corners
  // feel it too
  if (d_lo == 0)
    f += dual_cell_volumetric_force(e, ui, u, cell_of, grid, sy, sz, h, tissue_of, materials, rest_offset,
                                    VB_PENDING_ARGS);
#endif
  return f;
}

VB_INLINE real4 lattice_force(uint e, real4 ui, real4 vi, global const real4* u, global const real4* v,
                              VB_LATTICE_PARAMS) {
  return lattice_force_pending(e, ui, vi, u, v, VB_LATTICE_ARGS, VB_NO_PENDING, 0, 26, 0, u);
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
// Row columns (kernels/common.cl, VB_IND_STRIDE): the path is start + velocity·clamp(t − t0, 0,
// travel), so the host can move an indenter between steps by rewriting one row (a recorded
// trajectory, quasi-static presses) without touching the kernels.
inline real4 indenter_position(global const real* ind, real t) {
  const real tt = clamp(t - ind[16], (real)0, ind[12]);
  return (real4)(ind[0] + ind[8] * tt, ind[1] + ind[9] * tt, ind[2] + ind[10] * tt, 0);
}

inline real4 indenter_velocity(global const real* ind, real t) {
  const real tt = t - ind[16];
  return tt >= 0 && tt < ind[12] ? (real4)(ind[8], ind[9], ind[10], 0) : (real4)(0);
}

// Signed distance from the indenter surface at time t (m, < 0 inside) and the outward normal.
// Kinds (column 14): 0 sphere (centre, radius), 1 plate (point, normal into the tissue),
// 2 flat-ended cylinder (centre of the flat end, axis = press direction, radius; the body extends
// backwards from the end face), 3 capsule (segment from the start along the axis over column 15's
// length, radius): a finger.
inline real indenter_distance(real4 x, global const real* ind, real t, real4* n_out) {
  const real4 p = indenter_position(ind, t);
  const int kind = (int)ind[14];
  const real4 d = xyz0(x - p);
  const real4 a = (real4)(ind[4], ind[5], ind[6], 0);
  if (kind == 1) {
    *n_out = a;
    return dot3(d, a);
  }
  if (kind == 2) {
    const real s = dot3(d, a);  // > 0: ahead of the end face
    const real4 radial = d - s * a;
    const real r = length(radial);
    const real4 er = r > 0 ? radial / r : (real4)(0);
    const real out = r - ind[3];  // > 0: beside the side wall
    if (s > 0 && out > 0) {       // off the rim: nearest point is on the edge circle
      const real dist = sqrt(s * s + out * out);
      *n_out = (s * a + out * er) / dist;
      return dist;
    }
    if (s > 0 || (out <= 0 && s >= out)) {  // in front of the face, or inside and nearer the face
      *n_out = a;
      return s;
    }
    *n_out = er;  // beside the wall, or inside and nearer the wall
    return out;
  }
  real4 c = p;
  if (kind == 3) c = p + clamp(dot3(d, a), (real)0, ind[15]) * a;  // nearest point of the segment
  const real4 dc = xyz0(x - c);
  const real dist = length(dc);
  *n_out = dist > 0 ? dc / dist : (real4)(0, 0, 1, 0);
  return dist - ind[3];
}

// Contact of a touching element (within REAL_CONTACT_TOL·h of the surface). Push: unilateral,
// the indenter carries the inward normal part of the element's force that would take it into the
// indenter; with a friction coefficient μ (column 17) it adds μ·|f_n| to the element's grip
// (device_contact.cl: Coulomb friction at the velocity level, against the indenter's velocity).
// Slide: held on the surface, the indenter carries the whole normal part (pull too), the element
// slides freely along it. Stick: the element moves with the indenter, which carries all of its force.
// Returns the part carried (force on the indenter, N) and removes it from f.
// A push carries only what would take the element through the surface within the stage, which
// ends near x + lead·v + reach·f (reach, m/N: the stage's gain on the acceleration over the
// element's mass, fictitious under relaxation; device_contact.cl, push_carried); reach 0 (the
// check) carries all of it.
inline real4 contact_constrain(real4* f, real4 x, real4 v, real lead, real reach, global const real* ind, real t, real h,
                               torus_grip* grip) {
#if VB_TRI_CONTACT
  if (ind[18] != 0) return (real4)(0);  // contact with the surface triangles (triangle_contact.cl)
#endif
  real4 n;
  const real dist = indenter_distance(x, ind, t, &n);
  const int mode = (int)ind[13];
  if (dist > REAL_CONTACT_TOL * h || (mode != 0 && dist < -REAL_CONTACT_TOL * h)) return (real4)(0);
  if (mode == 2) {
    const real4 all = xyz0(*f);
    *f -= all;
    return all;
  }
  const real fn = dot3(*f, n);
  if (mode == 0 && fn >= 0) return (real4)(0);
  const real carried =
      mode == 0 ? push_carried(fn, dist, dot3(v - indenter_velocity(ind, t), n), lead, reach, contact_resolution(x)) : fn;
  *f -= carried * n;
#if VB_FRICTION
  if (mode == 0) grip_add(grip, carried, ind[17], n, indenter_velocity(ind, t));
#endif
  return carried * n;
}

inline void contact_constrain_all(real4* f, real4 x, real4 v, real lead, real reach, global const real* indenters,
                                  real t, real h, torus_grip* grip) {
  for (int i = 0; i < VB_INDENTERS; ++i)
    contact_constrain(f, x, v, lead, reach, indenters + VB_IND_STRIDE * i, t, h, grip);
}

// Moves an element that ended inside an indenter (deeper than contact_resolution) back onto its
// surface; its normal velocity becomes at least the indenter's (push). A held element (slide,
// stick) is put back on the surface and takes the indenter's normal velocity (slide) or its whole
// velocity (stick). Held means: within the contact tolerance of the surface where the stage began
// (x_start at t_start, the element whose force contact_constrain carried), or inside or within the
// tolerance where it ends (newly reached). The stage's start decides, not its end, so an indenter
// that moves further than the tolerance in one stage keeps the elements it holds.
inline void contact_project_all(real4* ui, real4* vi, real4 X, real4 x_start, global const real* indenters,
                                real t_start, real t, real h) {
  for (int i = 0; i < VB_INDENTERS; ++i) {
    global const real* ind = indenters + VB_IND_STRIDE * i;
    const int mode = (int)ind[13];
#if VB_TRI_CONTACT
    if (ind[18] != 0) continue;  // triangle contact: a force, not a projection
#endif
    real4 n;
    const real4 x = X + xyz0(*ui);
    const real dist = indenter_distance(x, ind, t, &n);
    if (mode == 0 && dist >= -contact_resolution(x)) continue;
    if (mode != 0 && dist > REAL_CONTACT_TOL * h) {
      real4 n_start;
      if (fabs(indenter_distance(x_start, ind, t_start, &n_start)) > REAL_CONTACT_TOL * h) continue;
    }
    *ui -= dist * n;
    const real4 w = indenter_velocity(ind, t);
    const real vn = dot3(*vi, n), wn = dot3(w, n);
    if (mode == 2) *vi = w;
    else if (mode == 1 || vn < wn) *vi += (wn - vn) * n;
  }
}
#endif

// Test entry point: lattice forces only (N), for comparison with the host reference.
kernel void lattice_forces(global const real4* u, global const real4* v, VB_LATTICE_KERNEL_PARAMS, global real4* f_out,
                           uint n) {
  VB_UNPACK_LATTICE;
  const uint e = get_global_id(0);
  if (e >= n) return;
  f_out[e] = lattice_force(e, u[e], v[e], u, v, VB_LATTICE_ARGS);
}
