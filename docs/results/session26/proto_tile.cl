// Session 26 prototype (docs/PERF_NOTES.md, attempt 33; not part of the build), from session 25's
// proto_walk.cl: the same stage pair (main's short connection loop, layout 5: the state as u, v
// float4, the predicted stage packed), with the elements a work-group steps chosen by ORDER:
//   0: e = the global id (row order, as main without a step list)
//   1: e = L[global id], L the identity (what the list's own read costs)
//   2: e = L[global id], L the free elements in tiles of TX × TY × TZ cells (x fastest inside a tile)
//   3: the tile computed from the group id, no list: a group steps one TX × TY × TZ tile (lanes
//      past the cube's edge step nothing)
// The state stays in row order in every case: only which elements a group takes together changes,
// so a group's neighbour rows (its L1 footprint) shrink from ~4.2 × 3 rows to (TY + 2) × (TZ + 2)
// row pieces of TX + 2.
// REVERSE (ORDER 0; PROTO_REVERSE=1 sets it for the second stage, attempt 35): the stage steps the
// elements from the last to the first, so it starts where the first stage ended, on the lines
// most recently written (the predicted stage still in L2), and ends where the next step's first
// stage starts.
#ifndef ORDER
#define ORDER 0
#endif
#ifndef REVERSE
#define REVERSE 0
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


kernel void stage(global const float* src, global const float* base, global float* out, global const float* W,
                  global const float* E, global const int* grid, global const uint* cell_of, global const uint* L,
                  int sy, int sz, float h, float dt, float zeta, int second, uint n) {
#if ORDER == 0 && REVERSE  // the elements in reverse order (PROTO_REVERSE: the second stage)
  if (get_global_id(0) >= n) return;
  const uint e = n - 1 - get_global_id(0);
#elif ORDER == 0
  const uint e = get_global_id(0);
  if (e >= n) return;
#elif ORDER == 1 || ORDER == 2
  if (get_global_id(0) >= n) return;
  const uint e = L[get_global_id(0)];
#else
  const uint g = get_group_id(0), l = get_local_id(0);
  const uint ntx = (NC + TX - 1) / TX, nty = (NC + TY - 1) / TY;
  const uint x = (g % ntx) * TX + l % TX, y = ((g / ntx) % nty) * TY + (l / TX) % TY, z = (g / (ntx * nty)) * TZ + l / (TX * TY);
  if (x >= NC || y >= NC || z >= NC) return;
  const uint e = x + NC * (y + NC * z);
#endif
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
    const float3 vj = load_v(LSRC, src, j, n);
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
