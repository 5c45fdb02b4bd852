// Session 24 prototype (docs/PERF_NOTES.md, attempt 29): the short connection loop of main
// (lattice_force_uniform: one material, k and the dashpot's coefficient per direction) with the
// state in five layouts, to test whether the neighbour reads cost by the cache lines a warp's load
// touches (L1 wavefronts). Per neighbour the loop needs u.xyz and v.xyz (24 B).
//   LAYOUT 0: u float4, v float4 (main): a warp's two loads touch 4 + 4 lines
//   LAYOUT 1: (u.x, u.y, u.z, v.x) float4 + (v.y, v.z) float2: 4 + 2 lines, still 2 loads
//   LAYOUT 2: six float arrays: 6 × 1 line, 6 loads
//   LAYOUT 3: timing only, no neighbour velocity read (the dashpot sees v_j = 0): 4 lines
//   LAYOUT 4: u float4, v as half4 (8 B): 4 + 2 lines, v rounded to 11 bits (accuracy changes)
//   LAYOUT 5 (the harness's "mixed"): the step's state in layout 0, its predicted stage in layout 1
//   (stage 1 reads 0, writes 1; stage 2 reads 1 and the base in 0, writes 0)
// Each state set is one arena of 32 B per element; W (inverse mass) and E in arrays of their own.
#ifndef LAYOUT
#define LAYOUT 0
#endif
constant int DX[26] = {-1,0,1,-1,0,1,-1,0,1, -1,0,1,-1,1,-1,0,1, -1,0,1,-1,0,1,-1,0,1};
constant int DY[26] = {-1,-1,-1,0,0,0,1,1,1, -1,-1,-1,0,0,1,1,1, -1,-1,-1,0,0,0,1,1,1};
constant int DZ[26] = {-1,-1,-1,-1,-1,-1,-1,-1,-1, 0,0,0,0,0,0,0,0, 1,1,1,1,1,1,1,1,1};
inline float kap(int d) { int m = abs(DX[d]) + abs(DY[d]) + abs(DZ[d]); return m == 1 ? 0.5f : m == 2 ? 0.25f : 0.125f; }
inline float skap(int d) { int m = abs(DX[d]) + abs(DY[d]) + abs(DZ[d]); return m == 1 ? 0.70710678f : m == 2 ? 0.5f : 0.35355339f; }
inline float dlen(int d) { int m = abs(DX[d]) + abs(DY[d]) + abs(DZ[d]); return m == 1 ? 1.0f : m == 2 ? 1.41421356f : 1.73205081f; }

#ifndef LSRC  // a stage's source, the step's base and the stage's output may differ in layout
#define LSRC LAYOUT
#endif
#ifndef LBASE
#define LBASE LAYOUT
#endif
#ifndef LOUT
#define LOUT LAYOUT
#endif
// L is a compile-time constant at every call: each call folds to one layout's loads.
inline float3 load_u(int L, global const float* s, int j, uint n) {
  if (L == 2) return (float3)(s[j], s[n + j], s[2 * n + j]);
  return ((global const float4*)s)[j].xyz;
}
inline float3 load_v(int L, global const float* s, int j, uint n) {
  if (L == 1) {
    const float2 b = ((global const float2*)(s + 4 * n))[j];
    return (float3)(((global const float4*)s)[j].w, b.x, b.y);
  }
  if (L == 2) return (float3)(s[3 * n + j], s[4 * n + j], s[5 * n + j]);
  if (L == 4) return vload_half4(j, (global const half*)(s + 4 * n)).xyz;
  return ((global const float4*)(s + 4 * n))[j].xyz;  // 0 and 3 (which reads no neighbour's)
}
inline void store(int L, global float* s, int e, uint n, float3 u, float3 v) {
  if (L == 2) {
    s[e] = u.x; s[n + e] = u.y; s[2 * n + e] = u.z; s[3 * n + e] = v.x; s[4 * n + e] = v.y; s[5 * n + e] = v.z;
  } else if (L == 1) {
    ((global float4*)s)[e] = (float4)(u, v.x);
    ((global float2*)(s + 4 * n))[e] = v.yz;
  } else if (L == 4) {
    ((global float4*)s)[e] = (float4)(u, 0);
    vstore_half4_rte((float4)(v, 0), e, (global half*)(s + 4 * n));
  } else {
    ((global float4*)s)[e] = (float4)(u, 0);
    ((global float4*)(s + 4 * n))[e] = (float4)(v, 0);
  }
}

// One Heun stage: stage 1 reads src (= base) and writes the predicted state to out; stage 2 reads
// the predicted state from src, the step's base from base, and writes the corrected state.
kernel void stage(global const float* src, global const float* base, global float* out, global const float* W,
                  global const float* E, global const int* grid, global const uint* cell_of, int sy, int sz, float h,
                  float dt, float zeta, int second, uint n) {
  const uint e = get_global_id(0);
  if (e >= n) return;
  const int cell = (int)cell_of[e];
  const float3 ui = load_u(LSRC, src, e, n), vi = load_v(LSRC, src, e, n);
  const float wi = W[e], Ei = E[e];
  const float damping_e = 2 * zeta * sqrt(h * Ei / (2 * wi));
  float3 f = (float3)(0);
#pragma unroll
  for (int d = 0; d < 26; ++d) {
    const int jn = grid[cell + DX[d] + sy * DY[d] + sz * DZ[d]];
    const float present = jn >= 0 ? 1.0f : 0.0f;
    const int j = jn >= 0 ? jn : (int)e;
    const float3 uj = load_u(LSRC, src, j, n);
    const float3 r = (float3)(h * DX[d], h * DY[d], h * DZ[d]) + (uj - ui);
    const float len_sq = dot(r, r);
    const float inv = len_sq > 0 ? rsqrt(len_sq) : 0.0f;
    const float3 nn = r * inv;
    float mag = present * (kap(d) * h * Ei) * (len_sq * inv - h * dlen(d));
#if LSRC == 3
    const float3 vj = (float3)(0);
#else
    const float3 vj = load_v(LSRC, src, j, n);
#endif
    mag += present * (damping_e * skap(d)) * dot(vj - vi, nn);
    f += mag * nn;
  }
  float3 a = f * wi - vi;
  a.z -= 9.81f;
  if (wi == 0) {
    if (!second) store(LOUT, out, e, n, ui, vi);
    else store(LOUT, out, e, n, load_u(LBASE, base, e, n), load_v(LBASE, base, e, n));
  } else if (!second) {
    store(LOUT, out, e, n, ui + dt * vi, vi + dt * a);
  } else {
    const float3 ub = load_u(LBASE, base, e, n), vb = load_v(LBASE, base, e, n);
    store(LOUT, out, e, n, ub + 0.5f * dt * (vb + vi), 0.5f * (vb + vi) + 0.5f * dt * a);
  }
}

kernel void copy4(global const float4* a, global float4* b) { b[get_global_id(0)] = a[get_global_id(0)]; }
