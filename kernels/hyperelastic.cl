// Hyperelastic elements (compiled when VB_HYPER is 1). Pass 1, element_stress, computes each
// element's deformation gradient by least squares over its existing neighbours,
//   F = A·B⁻¹,  A = Σ Δx ΔXᵀ,  B = Σ ΔX ΔXᵀ  (ΔX = h·d rest offsets, Δx deformed),
// the first Piola-Kirchhoff stress P(F) of the law's isochoric part, and Q = V·P·B⁻¹ (stored with
// C = FᵀF: hyper_store). The volumetric part is not per element: it is the dual cells' energy
// (dual_cell_volumetric_force, gathered in pass 2). The energy V·W_iso(F_e) puts force −Q_e·(h·d) on each neighbour at offset h·d and +Q_e·Σ h·d on
// the element itself (pass 2 gathers them in lattice_force): total force and torque vanish and
// rigid motions give none.
//
// Material table (global const real*, VB_MAT_STRIDE reals per tissue):
//   0 law (0 linear springs, 1 neo-Hookean/Mooney-Rivlin by invariants, 2 Ogden by stretches,
//     3 biphasic springs)
//   1 terms N, 2..4 μ_p (Pa), 5..7 α_p, 8 κ (Pa)
//   9 c3, 10 εc (biphasic springs, kernels/lattice_forces.cl); 11 unused
// Laws 0 and 3 are spring tissues: no element stress (Q = 0, F = I).
#define VB_MAT_STRIDE 12
#define VB_LAW_BIPHASIC 3
#if VB_BIPHASIC
#define VB_LAW_HYPER(law) ((law) != 0 && (law) != VB_LAW_BIPHASIC)
#else
#define VB_LAW_HYPER(law) ((law) != 0)
#endif
#if VB_HYPER

typedef struct {
  real m[3][3];
} mat3;

inline mat3 mat3_zero(void) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = 0;
  return r;
}

inline mat3 mat3_identity(void) {
  mat3 r = mat3_zero();
  r.m[0][0] = r.m[1][1] = r.m[2][2] = 1;
  return r;
}

inline mat3 mat3_mul(mat3 a, mat3 b) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
  return r;
}

inline mat3 mat3_transpose_mul(mat3 a, mat3 b) {  // aᵀ·b
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[0][i] * b.m[0][j] + a.m[1][i] * b.m[1][j] + a.m[2][i] * b.m[2][j];
  return r;
}

inline mat3 mat3_transpose(mat3 a) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[j][i];
  return r;
}

inline real mat3_det(mat3 a) {
  return a.m[0][0] * (a.m[1][1] * a.m[2][2] - a.m[1][2] * a.m[2][1]) -
         a.m[0][1] * (a.m[1][0] * a.m[2][2] - a.m[1][2] * a.m[2][0]) +
         a.m[0][2] * (a.m[1][0] * a.m[2][1] - a.m[1][1] * a.m[2][0]);
}

inline mat3 mat3_inverse(mat3 a, real det) {
  mat3 r;
  const real s = 1 / det;
  r.m[0][0] = (a.m[1][1] * a.m[2][2] - a.m[1][2] * a.m[2][1]) * s;
  r.m[0][1] = (a.m[0][2] * a.m[2][1] - a.m[0][1] * a.m[2][2]) * s;
  r.m[0][2] = (a.m[0][1] * a.m[1][2] - a.m[0][2] * a.m[1][1]) * s;
  r.m[1][0] = (a.m[1][2] * a.m[2][0] - a.m[1][0] * a.m[2][2]) * s;
  r.m[1][1] = (a.m[0][0] * a.m[2][2] - a.m[0][2] * a.m[2][0]) * s;
  r.m[1][2] = (a.m[0][2] * a.m[1][0] - a.m[0][0] * a.m[1][2]) * s;
  r.m[2][0] = (a.m[1][0] * a.m[2][1] - a.m[1][1] * a.m[2][0]) * s;
  r.m[2][1] = (a.m[0][1] * a.m[2][0] - a.m[0][0] * a.m[2][1]) * s;
  r.m[2][2] = (a.m[0][0] * a.m[1][1] - a.m[0][1] * a.m[1][0]) * s;
  return r;
}

inline real4 mat3_apply(mat3 a, real4 v) {
  return (real4)(a.m[0][0] * v.x + a.m[0][1] * v.y + a.m[0][2] * v.z,
                 a.m[1][0] * v.x + a.m[1][1] * v.y + a.m[1][2] * v.z,
                 a.m[2][0] * v.x + a.m[2][1] * v.y + a.m[2][2] * v.z, 0);
}

// M·(h·d) for lattice direction d, skipping d's zero components: d is a constant once the
// neighbour loop is unrolled, and IEEE rules forbid the compiler to drop x·0 itself (a face
// direction takes 3 multiply-adds instead of 9). The same value as mat3_apply(M, h·d).
inline real4 mat3_apply_dir(mat3 a, int d, real h) {
  real4 r = (real4)(0);
  for (int b = 0; b < 3; ++b) {
    if (VB_DIR[d][b] == 0) continue;
    const real hb = h * VB_DIR[d][b];
    r.x += a.m[0][b] * hb;
    r.y += a.m[1][b] * hb;
    r.z += a.m[2][b] * hb;
  }
  return r;
}

// |F·r| from C = FᵀF (diag = C00, C11, C22; off = C01, C02, C12): √(rᵀ·C·r), floored at 0 against
// rounding for a crushed element.
inline real stretched_length(real4 diag, real4 off, real4 r) {
  const real s = r.x * r.x * diag.x + r.y * r.y * diag.y + r.z * r.z * diag.z +
                 2 * (r.x * r.y * off.x + r.x * r.z * off.y + r.y * r.z * off.z);
  return sqrt(fmax(s, (real)0));
}

// The same for r = h·d, with only d's nonzero terms (d is a constant once the loop is unrolled:
// a face direction is h·√C_aa, 1 of the 6 terms; the dropped terms are exact zeros).
inline real stretched_length_dir(real4 diag, real4 off, int d, real h) {
  const int x = VB_DIR[d][0], y = VB_DIR[d][1], z = VB_DIR[d][2];
  real s = 0;
  if (x) s += diag.x;
  if (y) s += diag.y;
  if (z) s += diag.z;
  if (x * y) s += (real)(2 * x * y) * off.x;
  if (x * z) s += (real)(2 * x * z) * off.y;
  if (y * z) s += (real)(2 * y * z) * off.z;
  return h * sqrt(fmax(s, (real)0));
}

inline void mat3_store(global real4* rows, uint e, mat3 a) {
  for (int i = 0; i < 3; ++i) rows[3 * e + i] = (real4)(a.m[i][0], a.m[i][1], a.m[i][2], 0);
}

// The force pass's per-element data (pass 2 reads it for all 26 neighbours, so it is packed into 4
// real4): rows of Q with C = FᵀF's diagonal in w, then (C01, C02, C12, 1 if the element's tissue is
// hyperelastic else 0). C gives the hourglass control's |F·r₀| = √(r₀ᵀ·C·r₀) without F (3 loads
// fewer per neighbour) and the flag the neighbour's law without its tissue id and material row.
inline void hyper_store(global real4* Qs, global real4* Cs, uint e, mat3 Q, mat3 C, int hyper) {
  for (int i = 0; i < 3; ++i) Qs[3 * e + i] = (real4)(Q.m[i][0], Q.m[i][1], Q.m[i][2], C.m[i][i]);
  Cs[e] = (real4)(C.m[0][1], C.m[0][2], C.m[1][2], hyper ? 1 : 0);
}

inline mat3 mat3_load(global const real4* rows, uint e) {
  mat3 a;
  for (int i = 0; i < 3; ++i) {
    const real4 r = rows[3 * e + i];
    a.m[i][0] = r.x;
    a.m[i][1] = r.y;
    a.m[i][2] = r.z;
  }
  return a;
}

// J clamped for the isochoric terms: W_iso uses J_c = max(J, floor), so below the floor J_c is a
// constant and the isochoric stress has no C⁻¹ (J-derivative) term and stays finite for a crushed
// (J = 0) or inverted (J < 0) element. The volumetric energy is not the element's: it is that of
// the dual cells (dual_cell_volumetric_force below), whose κ(J_c − 1) pushes a crushed or inverted
// cell back towards J_c = 1.
#define VB_J_FLOOR ((real)0.05)

// Isochoric second Piola-Kirchhoff stress of Mooney-Rivlin (neo-Hookean when C01 = 0) from
// invariants: S = 2C10 J^(−2/3)(I − I1/3 C⁻¹) + 2C01 J^(−4/3)(I1 I − C − 2/3 I2 C⁻¹) (the C⁻¹ terms
// only above the floor)
inline mat3 stress_invariants(mat3 C, real J, real c10, real c01) {
  const real I1 = C.m[0][0] + C.m[1][1] + C.m[2][2];
  real I2 = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) I2 -= C.m[i][j] * C.m[j][i];
  I2 = (real)0.5 * (I1 * I1 + I2);
  const real Jc = fmax(J, VB_J_FLOOR);
  const real a = 2 * c10 * pow(Jc, (real)(-2.0 / 3.0)), b = 2 * c01 * pow(Jc, (real)(-4.0 / 3.0));
  mat3 Ci = mat3_zero();  // C⁻¹ where J_c follows J; det C = J² ≥ floor² there
  if (J > VB_J_FLOOR) Ci = mat3_inverse(C, mat3_det(C));
  mat3 S;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const real id = i == j ? 1 : 0;
      S.m[i][j] = a * (id - I1 / 3 * Ci.m[i][j]) + b * (I1 * id - C.m[i][j] - (real)(2.0 / 3.0) * I2 * Ci.m[i][j]);
    }
  return S;
}

// Cyclic Jacobi eigen-decomposition of symmetric C: C = V·diag(w)·Vᵀ (robust when eigenvalues
// coincide, as at rest). An off-diagonal entry below rounding of its diagonal pair is not
// rotated (the rotation would change the result by rounding only), and the sweeps stop once a
// sweep rotates nothing: usually after 2–4 sweeps instead of all 8.
inline void eigen_symmetric(mat3 C, real w[3], mat3* V) {
  mat3 A = C;
  *V = mat3_identity();
  for (int sweep = 0; sweep < 8; ++sweep) {
    int rotated = 0;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        const real apq = A.m[p][q];
        if (fabs(apq) < (real)1e-30 || fabs(apq) <= VB_EPSILON * (fabs(A.m[p][p]) + fabs(A.m[q][q]))) continue;
        rotated = 1;
        const real theta = (A.m[q][q] - A.m[p][p]) / (2 * apq);
        const real t = sign(theta) / (fabs(theta) + sqrt(theta * theta + 1)) + (theta == 0 ? 1 : 0);
        const real c = 1 / sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {  // A ← Jᵀ A J
          const real akp = A.m[k][p], akq = A.m[k][q];
          A.m[k][p] = c * akp - s * akq;
          A.m[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {
          const real apk = A.m[p][k], aqk = A.m[q][k];
          A.m[p][k] = c * apk - s * aqk;
          A.m[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {
          const real vkp = V->m[k][p], vkq = V->m[k][q];
          V->m[k][p] = c * vkp - s * vkq;
          V->m[k][q] = s * vkp + c * vkq;
        }
      }
    if (!rotated) break;
  }
  for (int i = 0; i < 3; ++i) w[i] = A.m[i][i];
}

// Isochoric Ogden stress from principal stretches: τ_i = Σ_p μ_p(λ̄_i^α_p − ⅓Σ_k λ̄_k^α_p) (the ⅓Σ
// term only above the floor); S = Σ τ_i/λ_i² N_i N_iᵀ.
inline mat3 stress_ogden(mat3 C, real J, global const real* mat) {
  real w[3];
  mat3 N;
  eigen_symmetric(C, w, &N);
  const real Jc = fmax(J, VB_J_FLOOR);
  const real mean = J > VB_J_FLOOR ? (real)(1.0 / 3.0) : 0;
  // λ̄_i^α = exp(α·ln λ̄_i), ln λ̄_i = ½ ln w_i − ⅓ ln J_c: three logarithms shared by all terms
  // instead of a pow per stretch and term
  const real log_scale = (real)(-1.0 / 3.0) * log(Jc);
  real tau[3];
  real log_lbar[3];
  for (int i = 0; i < 3; ++i) {
    w[i] = fmax(w[i], (real)1e-12);
    log_lbar[i] = (real)0.5 * log(w[i]) + log_scale;
    tau[i] = 0;
  }
  const int terms = (int)mat[1];
  for (int p = 0; p < terms; ++p) {
    const real mu = mat[2 + p], alpha = mat[5 + p];
    real la[3], sum = 0;
    for (int i = 0; i < 3; ++i) {
      la[i] = exp(alpha * log_lbar[i]);
      sum += la[i];
    }
    for (int i = 0; i < 3; ++i) tau[i] += mu * (la[i] - mean * sum);
  }
  mat3 S = mat3_zero();
  for (int i = 0; i < 3; ++i) {
    const real f = tau[i] / w[i];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) S.m[a][b] += f * N.m[a][i] * N.m[b][i];
  }
  return S;
}

// Heun's predicted stage read from (u, v) (VB_STRESS_PAIR): heun_predict moves every free element
// to ũ = u + dt·v, whatever its force (kernels/integrate.cl, explicit_update, the same arithmetic),
// so its stress needs no predicted state in memory. `predicted` is a constant at every call.
#define VB_PREDICTED_PARAMS global const real4 *pred_v, real pred_dt, int predicted
#define VB_PREDICTED_ARGS pred_v, pred_dt, predicted
#define VB_NOT_PREDICTED (global const real4*)0, (real)0, 0
inline void predicted_u(real4* uj, uint j, VB_PREDICTED_PARAMS) {
  if (predicted && uj->w != 0) *uj += pred_dt * xyz0(pred_v[j]);
}

// Least-squares deformation gradient of element e from the displacements u of its existing
// neighbours: F = A·B⁻¹ (see the top of this file). Sets B⁻¹ (in units of 1/h²) and the bit mask
// of present neighbours; returns false when they do not span 3-D (a thin strand: no F). u is read
// as a pending volume projection leaves it (kernels/common.cl), or as Heun's predicted stage.
inline bool fit_gradient(global const real4* u, uint e, global const uint* cell_of, global const int* grid,
                         int sy, int sz, real h, mat3* F, mat3* Bi, uint* present_out, VB_PENDING_PARAMS,
                         VB_PREDICTED_PARAMS) {
  const int cell = (int)cell_of[e];
  real4 ue = u[e], wg = (real4)(0);
  pending_u(&ue, &wg, e, VB_PENDING_ARGS);
  predicted_u(&ue, e, VB_PREDICTED_ARGS);
  mat3 A = mat3_zero(), B = mat3_zero();  // B in units of h²
  uint present = 0;
#pragma unroll
  for (int d = 0; d < 26; ++d) {
    const int j = grid[cell + VB_DIR[d][0] + sy * VB_DIR[d][1] + sz * VB_DIR[d][2]];
    if (j < 0) continue;
    present |= 1u << d;
    real4 uj = u[j];
    pending_u(&uj, &wg, (uint)j, VB_PENDING_ARGS);
    predicted_u(&uj, (uint)j, VB_PREDICTED_ARGS);
    const real dX[3] = {VB_DIR[d][0], VB_DIR[d][1], VB_DIR[d][2]};
    const real dx[3] = {h * dX[0] + (uj.x - ue.x), h * dX[1] + (uj.y - ue.y), h * dX[2] + (uj.z - ue.z)};
    // only d's nonzero components (constants once unrolled): adding x·0 changes nothing, but the
    // compiler may not drop it under IEEE rules
    for (int b = 0; b < 3; ++b) {
      if (VB_DIR[d][b] == 0) continue;
      for (int a = 0; a < 3; ++a) {
        A.m[a][b] += dx[a] * dX[b];  // in units of h (dX dimensionless)
        B.m[a][b] += dX[a] * dX[b];
      }
    }
  }
  *present_out = present;
  const real detB = mat3_det(B);
  if (detB < (real)0.5) return false;
  *Bi = mat3_inverse(B, detB);
  *F = mat3_mul(A, *Bi);
  const real inv_h = 1 / h;  // one division instead of nine (each a call sequence on NVIDIA)
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) F->m[a][b] *= inv_h;
  return true;
}

// The arena's arrays the gradient fit reads (kernels/common.cl, VB_UNPACK_LATTICE).
#define VB_UNPACK_FIT                                                                    \
  global const uint* cell_of = (global const uint*)VB_ARENA_AT(arena, at.s1);           \
  global const int* grid = (global const int*)VB_ARENA_AT(arena, at.s2);                \
  global const uchar* tissue_of = VB_ARENA_AT(arena, at.s3);                            \
  global const real* materials = (global const real*)VB_ARENA_AT(arena, at.s4)

// Pass 1: per-element Q and C (hyper_store; in the arena, kernels/common.cl). The element's volume
// is w·h³, w = (complete dual cells around it)/8 (engine/lattice/dual_cells.hpp): then a
// homogeneous stress is balanced by forces on the surface elements alone, as plates apply them.
// With VB_REST_OFFSET the element rests in the unloaded state, whose gradient from the lattice is
// F₀ (rest_frame: rows of R₀ = F₀⁻¹, J₀ = det F₀ in row 0's w): the law sees F·R₀ and the energy
// J₀·V·W(F·R₀) gives Q = J₀·V·P(F·R₀)·R₀ᵀ·B⁻¹ on the same lattice offsets. C_out is that of the
// deformation from rest (F·R₀), which the hourglass control applies to the rest connections.
// u may have a volume projection pending (VB_PENDING_PARAMS: VB_VOLUME_FOLD's element_stress), or
// be read as Heun's predicted stage (VB_PREDICTED_PARAMS: VB_STRESS_PAIR's).
// element_stress_one is element e's share, for element_stress below and for the persistent Heun
// step (kernels/persistent.cl).
inline void element_stress_one(uint e, global const real4* u, global uchar* arena, uint8 at, int sy, int sz, real h,
                               global const real4* rest_frame, VB_PENDING_PARAMS, VB_PREDICTED_PARAMS) {
  VB_UNPACK_FIT;
  global real4* Q_out = (global real4*)VB_ARENA_AT(arena, at.s5);  // written here (hyper_store)
  global real4* C_out = (global real4*)VB_ARENA_AT(arena, at.s6);
  global const real* mat = materials + VB_MAT_STRIDE * tissue_of[e];
  const int law = (int)mat[0];
  mat3 F, Bi;
  uint present = 0;
  // spring tissue, or neighbours that do not span 3-D: no element stress
  if (!VB_LAW_HYPER(law) || !fit_gradient(u, e, cell_of, grid, sy, sz, h, &F, &Bi, &present, VB_PENDING_ARGS,
                                                VB_PREDICTED_ARGS)) {
    hyper_store(Q_out, C_out, e, mat3_zero(), mat3_identity(), VB_LAW_HYPER(law));
    return;
  }
#if VB_REST_OFFSET
  const mat3 R0 = mat3_load(rest_frame, e);
  const real J0 = rest_frame[3 * e].w;
  F = mat3_mul(F, R0);
#endif
  const real J = mat3_det(F);
  const mat3 C = mat3_transpose_mul(F, F);
  const mat3 S = law == 1 ? stress_invariants(C, J, (real)0.5 * mat[2], (real)-0.5 * mat[3])
                          : stress_ogden(C, J, mat);
  mat3 P = mat3_mul(F, S);  // isochoric only: the volumetric energy is the dual cells' (below)
#if VB_REST_OFFSET
  P = mat3_mul(P, mat3_transpose(R0));
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) P.m[a][b] *= J0;
#endif
  int cells = 0;
  for (int o = 0; o < 8; ++o) cells += (present & VB_OCTANT_MASK[o]) == VB_OCTANT_MASK[o];
  mat3 Q = mat3_mul(P, Bi);  // V·P·B⁻¹ with V = w·h³ and B = h²·B' → w·h·P·B'⁻¹
  const real wh = (real)0.125 * cells * h;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) Q.m[a][b] *= wh;
  hyper_store(Q_out, C_out, e, Q, C, 1);
}

// With VB_VOLUME_FOLD, u may have a volume projection pending: its gradient pend_g and scalars
// {λ, μ, …} (all zero when none is).
// With VB_STRESS_PAIR (Heun), a launch over two rows of work-items computes both stages' stresses:
// row 0 that of u into Q, C (slots 5, 6), row 1 that of the predicted stage u + dt·v into the
// arena's slots pred_at (what heun_correct reads). One row is the stress of u alone (checks).
// In the step, with list_n > 0, work-item i takes element list[i] of the arena's list at list_at:
// only the elements some free element reads (Simulator, elements_read_by_free).
// u, the rest frame, the pending projection's gradient and scalars and v are state arena offsets
// (kernels/common.cl, VB_STATE_PARAM).
kernel void element_stress(uint u_at, global uchar* arena, uint8 at, int sy, int sz, real h, uint n,
                           uint rest_frame_at
#if VB_VOLUME_FOLD
                           , uint pend_g_at, uint pend_scalars_at
#endif
#if VB_STRESS_PAIR
                           , uint v_at, real dt, uint2 pred_at, uint list_at, uint list_n
#endif
                           VB_STATE_PARAM) {
  global const real4* u = VB_STATE_AT(const real4, u_at);
  global const real4* rest_frame = VB_STATE_AT(const real4, rest_frame_at);
#if VB_VOLUME_FOLD
  global const real4* pend_g = VB_STATE_AT(const real4, pend_g_at);
  global const real* pend_scalars = VB_STATE_AT(const real, pend_scalars_at);
#endif
#if VB_STRESS_PAIR
  global const real4* v = VB_STATE_AT(const real4, v_at);
#endif
  uint e = get_global_id(0);
#if VB_STRESS_PAIR
  if (list_n) {
    if (e >= list_n) return;
    e = ((global const uint*)VB_ARENA_AT(arena, list_at))[e];
  }
#endif
  if (e >= n) return;
#if VB_STRESS_PAIR
  if (get_global_id(1) == 1) {
    at.s5 = pred_at.x;
    at.s6 = pred_at.y;
    element_stress_one(e, u, arena, at, sy, sz, h, rest_frame, VB_NO_PENDING, v, dt, 1);
    return;
  }
#endif
#if VB_VOLUME_FOLD
  element_stress_one(e, u, arena, at, sy, sz, h, rest_frame, pend_g, pend_scalars[0], (real)0, 1, VB_NOT_PREDICTED);
#else
  element_stress_one(e, u, arena, at, sy, sz, h, rest_frame, VB_NO_PENDING, VB_NOT_PREDICTED);
#endif
}

#if VB_REST_OFFSET
// The unloaded state's frame per element, once per rest state: R₀ = F₀⁻¹ (rows, 3 real4) and
// J₀ = det F₀ (row 0's w), F₀ the same least-squares fit of the rest offsets u0 (identity for
// spring tissue and thin strands, which element_stress does not use).
kernel void rest_frame(global const real4* u0, global const uchar* arena, uint8 at, int sy, int sz, real h,
                       global real4* frame_out, uint n) {
  VB_UNPACK_FIT;
  const uint e = get_global_id(0);
  if (e >= n) return;
  const int law = (int)materials[VB_MAT_STRIDE * tissue_of[e]];
  mat3 F0, Bi;
  uint present = 0;
  real J0 = 1;
  mat3 R0 = mat3_identity();
  if (VB_LAW_HYPER(law) && fit_gradient(u0, e, cell_of, grid, sy, sz, h, &F0, &Bi, &present, VB_NO_PENDING, VB_NOT_PREDICTED)) {
    J0 = mat3_det(F0);
    R0 = mat3_inverse(F0, J0);
  }
  mat3_store(frame_out, e, R0);
  frame_out[3 * e].w = J0;
}
#endif
// Volumetric energy from the dual cells (docs/PHYSICS.md, "Volumetric energy"). A dual cell is
// the trilinear hexahedron whose 8 corners are neighbouring element centres; the body of
// hyperelastic tissue is the union of the complete ones, so their volumes add up to the body's
// volume and no non-affine (swirling, sliding) state can hide a change of it. Cell c carries
//   V0_c·κ_c/2·(J_c − 1)²,   J_c = V_c/V0_c,   κ_c = ⅛·Σ_corners κ (0 for spring tissue),
// so its corner a feels −κ_c·(J_c − 1)·∂V_c/∂x_a. Each element gathers this from the ≤ 8 complete
// cells around it (no scatter, no atomics), computing their volumes from its 3×3×3 neighbourhood.

// The two Gauss points on [0, 1]: (1 ∓ 1/√3)/2.
#define VB_GAUSS_LO ((real)0.21132486540518711775)
#define VB_GAUSS_HI ((real)0.78867513459481288225)

// Volume of the trilinear hexahedron with corners q[i + 2j + 4k] (local coordinates (i, j, k) ∈
// {0, 1}³; q[0] is the corner the gradient is taken at) and that volume's gradient with respect to
// q[0] in g0. V = ∫ det(∂x/∂ξ) dξ over the unit cube; det(∂x/∂ξ) has degree ≤ 2 in each of ξ, η,
// ζ, so the 2×2×2 Gauss rule is exact. ∂V/∂q[0] = ∫ cof(∂x/∂ξ)·∇_ξN₀ dξ with the same rule,
// N₀ = (1 − ξ)(1 − η)(1 − ζ). Negative when the local axes are left-handed.
inline real trilinear_volume_grad0(const real4 q[8], real4* g0) {
  // edge vectors along ξ (e_x), η (e_y) and ζ (e_z), each at its 4 positions (i, j, k bits)
  const real4 ex[4] = {q[1] - q[0], q[3] - q[2], q[5] - q[4], q[7] - q[6]};
  const real4 ey[4] = {q[2] - q[0], q[3] - q[1], q[6] - q[4], q[7] - q[5]};
  const real4 ez[4] = {q[4] - q[0], q[5] - q[1], q[6] - q[2], q[7] - q[3]};
  real V = 0;
  real4 g = (real4)(0);
  for (int gp = 0; gp < 8; ++gp) {
    const real s = gp & 1 ? VB_GAUSS_HI : VB_GAUSS_LO, t = gp & 2 ? VB_GAUSS_HI : VB_GAUSS_LO,
               r = gp & 4 ? VB_GAUSS_HI : VB_GAUSS_LO;
    const real4 xs = (1 - t) * (1 - r) * ex[0] + t * (1 - r) * ex[1] + (1 - t) * r * ex[2] + t * r * ex[3];
    const real4 xt = (1 - s) * (1 - r) * ey[0] + s * (1 - r) * ey[1] + (1 - s) * r * ey[2] + s * r * ey[3];
    const real4 xr = (1 - s) * (1 - t) * ez[0] + s * (1 - t) * ez[1] + (1 - s) * t * ez[2] + s * t * ez[3];
    const real4 c_s = cross(xt, xr), c_t = cross(xr, xs), c_r = cross(xs, xt);  // columns of cof
    V += dot3(xs, c_s);
    g -= (1 - t) * (1 - r) * c_s + (1 - s) * (1 - r) * c_t + (1 - s) * (1 - t) * c_r;
  }
  *g0 = (real)0.125 * g;
  return (real)0.125 * V;
}

// Force on element e from the volumetric energy of the complete dual cells around it (N). ui is
// e's displacement as the caller has it (pending projection applied); the neighbours' are read from
// u as lattice_force_pending reads them. Rest volumes are h³, or with VB_REST_OFFSET those of the
// unloaded state's cells.
inline real4 dual_cell_volumetric_force(uint e, real4 ui, global const real4* u, global const uint* cell_of,
                                        global const int* grid, int sy, int sz, real h,
                                        global const uchar* tissue_of, global const real* materials,
                                        global const real4* rest_offset, VB_PENDING_PARAMS) {
  const int cell = (int)cell_of[e];
  real4 x[27];  // neighbourhood positions relative to e, index (i + 1) + 3(j + 1) + 9(k + 1)
  real kappa[27];
#if VB_REST_OFFSET
  real4 x0[27];
  const real4 u0e = rest_offset[e];
#endif
  for (int m = 0; m < 27; ++m) {
    const int di = m % 3 - 1, dj = (m / 3) % 3 - 1, dk = m / 9 - 1;
    const int jn = m == 13 ? (int)e : grid[cell + di + sy * dj + sz * dk];
    const uint j = jn >= 0 ? (uint)jn : e;  // a missing neighbour reads e and carries κ = 0
    real4 uj = u[j], wg = (real4)(0);
    if (m != 13) pending_u(&uj, &wg, j, VB_PENDING_ARGS);
    else uj = ui;
    const real4 hd = (real4)(h * di, h * dj, h * dk, 0);
    x[m] = hd + xyz0(uj - ui);
    kappa[m] = jn >= 0 ? materials[VB_MAT_STRIDE * tissue_of[j] + 8] : (real)-1;  // −1: absent
#if VB_REST_OFFSET
    x0[m] = hd + xyz0(rest_offset[j] - u0e);
#endif
  }
  real4 f = (real4)(0);
  for (int o = 0; o < 8; ++o) {  // the cell in octant (±1, ±1, ±1) of e
    const int si = o & 1 ? -1 : 1, sj = o & 2 ? -1 : 1, sk = o & 4 ? -1 : 1;
    real4 q[8];
    real kappa_sum = 0;
    int complete = 1;
#if VB_REST_OFFSET
    real4 q0[8];
#endif
    for (int c = 0; c < 8; ++c) {
      const int m = (1 + si * (c & 1)) + 3 * (1 + sj * ((c >> 1) & 1)) + 9 * (1 + sk * ((c >> 2) & 1));
      q[c] = x[m];
      complete &= kappa[m] >= 0;
      kappa_sum += fmax(kappa[m], (real)0);
#if VB_REST_OFFSET
      q0[c] = x0[m];
#endif
    }
    if (!complete || kappa_sum == 0) continue;
    real4 g;
    const real V = trilinear_volume_grad0(q, &g);  // both carry the local axes' handedness si·sj·sk
#if VB_REST_OFFSET
    real4 g_unused;
    const real V0 = trilinear_volume_grad0(q0, &g_unused);
#else
    const real V0 = (real)(si * sj * sk) * h * h * h;
#endif
    // −κ_c(J_c − 1)·∂V_c/∂x_e: J_c = V/V0 (the handedness cancels), ∂V_c/∂x_e = si·sj·sk·g
    f -= (real)0.125 * kappa_sum * (V / V0 - 1) * (real)(si * sj * sk) * g;
  }
  return f;
}

#endif  // VB_HYPER
