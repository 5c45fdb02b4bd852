// Session 25 prototype (docs/PERF_NOTES.md, attempt 30), from session 24's proto_layout.cl: each
// work-group steps WALK consecutive blocks of elements in turn (WALK = 1: one block, as main), so
// the neighbour rows a block reads stay in the SM's L1 for the next block. Session 24's header:
// the short connection loop of main
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
#ifndef SHFL
#define SHFL 0
#endif
#if SHFL
// lane l receives lane l + 1's x (down) or lane l − 1's (up); the warp's end lanes their own.
inline uint shfl_from(uint x, int rx) {
  uint r;
  if (rx > 0) asm volatile("shfl.sync.down.b32 %0, %1, 1, 0x1f, 0xffffffff;" : "=r"(r) : "r"(x));
  else asm volatile("shfl.sync.up.b32 %0, %1, 1, 0x0, 0xffffffff;" : "=r"(r) : "r"(x));
  return r;
}
inline float3 shfl3(float3 a, int rx) {
  return (float3)(as_float(shfl_from(as_uint(a.x), rx)), as_float(shfl_from(as_uint(a.y), rx)),
                  as_float(shfl_from(as_uint(a.z), rx)));
}
#endif
#ifndef ROWS
#define ROWS 0
#endif
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
                  global const float* E, global const int* grid, global const uint* cell_of, global const uint* M, int sy, int sz, float h,
                  float dt, float zeta, int second, uint n) {
#ifndef WALK
#define WALK 1
#endif
 for (int it = 0; it < WALK; ++it) {
  const uint e_raw = (get_group_id(0) * WALK + it) * get_local_size(0) + get_local_id(0);
#if SHFL  // every lane of a warp takes part in the shuffles: the last warp's extra lanes store nothing
  const uint e = min(e_raw, n - 1);
#else
  const uint e = e_raw;
  if (e >= n) return;
#endif
  const int cell = (int)cell_of[e];
  const float3 ui = load_u(LSRC, src, e, n), vi = load_v(LSRC, src, e, n);
  const float wi = W[e], Ei = E[e];
  const float damping_e = 2 * zeta * sqrt(h * Ei / (2 * wi));
  float3 f = (float3)(0);
#if ROWS
  const uint mask = M[e];
#pragma unroll
  for (int rz = -1; rz <= 1; ++rz)
#pragma unroll
  for (int ry = -1; ry <= 1; ++ry) {
    const int c0 = cell + sy * ry + sz * rz;
    const int self_row = ry == 0 && rz == 0;
    const int dc = (rz + 1) * 9 + (ry + 1) * 3 + 1 - ((rz + 1) * 9 + (ry + 1) * 3 + 1 > 13);
    const int jc = self_row ? (int)e : grid[c0];
    const int centre_ok = self_row || ((mask >> dc) & 1);
#if SHFL
    const int jl = centre_ok ? jc : (int)e;  // the element whose state this lane loads for the row
    float3 uc = ui, vc = vi;
    if (!self_row) {
      uc = load_u(LSRC, src, jl, n);
      vc = load_v(LSRC, src, jl, n);
    }
#endif
#pragma unroll
  for (int rx = -1; rx <= 1; ++rx) {
    if (self_row && rx == 0) continue;
    const int d = (rz + 1) * 9 + (ry + 1) * 3 + (rx + 1) - ((rz + 1) * 9 + (ry + 1) * 3 + (rx + 1) > 13);
    const int has = (mask >> d) & 1;
    const int jr = rx == 0 ? jc : (centre_ok ? jc + rx : grid[c0 + rx]);
    const float present = has ? 1.0f : 0.0f;
    const int j = has ? jr : (int)e;
#else
#pragma unroll
  for (int d = 0; d < 26; ++d) {
    const int jn = grid[cell + DX[d] + sy * DY[d] + sz * DZ[d]];
    const float present = jn >= 0 ? 1.0f : 0.0f;
    const int j = jn >= 0 ? jn : (int)e;
#endif
#if SHFL
    float3 uj = uc, vj = vc;
    if (rx != 0) {
      const int js = (int)shfl_from((uint)jl, rx);
      uj = shfl3(uc, rx);
      vj = shfl3(vc, rx);
      if (js != j) {  // the neighbouring lane's centre is not this neighbour: read it
        uj = load_u(LSRC, src, j, n);
        vj = load_v(LSRC, src, j, n);
      }
    }
#else
    const float3 uj = load_u(LSRC, src, j, n);
#endif
    const float3 r = (float3)(h * DX[d], h * DY[d], h * DZ[d]) + (uj - ui);
    const float len_sq = dot(r, r);
    const float inv = len_sq > 0 ? rsqrt(len_sq) : 0.0f;
    const float3 nn = r * inv;
    float mag = present * (kap(d) * h * Ei) * (len_sq * inv - h * dlen(d));
#if SHFL
#elif LSRC == 3
    const float3 vj = (float3)(0);
#else
    const float3 vj = load_v(LSRC, src, j, n);
#endif
    mag += present * (damping_e * skap(d)) * dot(vj - vi, nn);
    f += mag * nn;
  }
#if ROWS
  }
#endif
#if SHFL
  if (e_raw >= n) return;
#endif
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
}

kernel void copy4(global const float4* a, global float4* b) { b[get_global_id(0)] = a[get_global_id(0)]; }
