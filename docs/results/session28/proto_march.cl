// Session 28 prototype (docs/PERF_NOTES.md, attempt 37; not part of the build), session 27's
// proto_march.cl with ORDER 8 added (the march in column order, at the end) and MIN, the
// connection in fewer instructions (ORDERs 0 and 8); run by session 27's proto_march.cpp
// (docs/results/session27/, unchanged: g++ -O2 -std=c++20 proto_march.cpp -o proto_march
// -lOpenCL). From session 26's
// proto_tile.cl: the same stage pair (main's short connection loop, layout 5: the state as u, v
// float4, the predicted stage packed). ORDER 0 is main's gather (a work-item per element, 27
// cells read per element and stage); ORDER 4 marches a work-item up a column of TZ cells along z
// (below), reading each of the 9 neighbouring columns' TZ + 2 cells once: 9 (TZ + 2) / TZ cells
// per element instead of 27, each held in registers for the three connections it serves.
// ORDER 5: the march without branches; 6: with computed indices (no grid reads, dense cube only);
// 7: two work-items per column piece. LEAN=1: the connection with fewer instructions (all
// orders). docs/PERF_NOTES.md "Session 27" has the results.
#ifndef ORDER
#define ORDER 0
#endif
#ifndef REVERSE
#define REVERSE 0
#endif
#ifndef LAYOUT
#define LAYOUT 0
#endif
// |x| for x in {-1, 0, 1} as x·x: NVIDIA's abs() is inline assembly, which kept the compiler from
// folding each direction's class (session 27's copy selected κ, √κ and L₀ at run time).
#define ABS1(x) ((x) * (x))
constant int DX[26] = {-1,0,1,-1,0,1,-1,0,1, -1,0,1,-1,1,-1,0,1, -1,0,1,-1,0,1,-1,0,1};
constant int DY[26] = {-1,-1,-1,0,0,0,1,1,1, -1,-1,-1,0,0,1,1,1, -1,-1,-1,0,0,0,1,1,1};
constant int DZ[26] = {-1,-1,-1,-1,-1,-1,-1,-1,-1, 0,0,0,0,0,0,0,0, 1,1,1,1,1,1,1,1,1};
inline float kap(int d) { int m = ABS1(DX[d]) + ABS1(DY[d]) + ABS1(DZ[d]); return m == 1 ? 0.5f : m == 2 ? 0.25f : 0.125f; }
inline float skap(int d) { int m = ABS1(DX[d]) + ABS1(DY[d]) + ABS1(DZ[d]); return m == 1 ? 0.70710678f : m == 2 ? 0.5f : 0.35355339f; }
inline float dlen(int d) { int m = ABS1(DX[d]) + ABS1(DY[d]) + ABS1(DZ[d]); return m == 1 ? 1.0f : m == 2 ? 1.41421356f : 1.73205081f; }

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


#ifndef LEAN
#define LEAN 0
#endif
// LEAN (attempt 36d): the connection with fewer instructions: n = r/|r| never formed (the dashpot's
// projection and the force's scale take 1/|r| as a scalar), rsqrt of max(|r|², tiny) in place of a
// select. Same physics, rounding differs.
inline float3 conn_lean(float3 ui, float3 vi, float kE, float cD, float3 uj, float3 vj, int dx, int dy, int dz, float h) {
  const int m = ABS1(dx) + ABS1(dy) + ABS1(dz);
  const float dl = m == 1 ? 1.0f : m == 2 ? 1.41421356f : 1.73205081f;
  const float3 r = (float3)(h * dx, h * dy, h * dz) + (uj - ui);
  const float len_sq = dot(r, r);
  const float inv = rsqrt(fmax(len_sq, 1e-30f));
  const float s = kE * (len_sq * inv - h * dl) + cD * dot(vj - vi, r) * inv;
  return (s * inv) * r;
}

#ifndef MIN
#define MIN 0
#endif
// MIN (attempt 37b): the connection in the fewest instructions found: per element (centre) the
// three direction classes' k = κ·h·E, k·L₀ and dashpot coefficient computed once, and per
// connection s = k − k·L₀/|r| + c·(Δv·r)/|r|² (the same force as (k(|r| − L₀) + c·Δv·r̂)·r̂),
// f += s·r; a missing neighbour masks s. Rounding differs from the gather's.
typedef struct { float k[3], kl[3], c[3]; } Coef;
inline Coef coef_of(float hE, float damp, float h) {
  Coef q;
  q.k[0] = 0.5f * hE; q.k[1] = 0.25f * hE; q.k[2] = 0.125f * hE;
  q.kl[0] = q.k[0] * h; q.kl[1] = q.k[1] * (h * 1.41421356f); q.kl[2] = q.k[2] * (h * 1.73205081f);
  q.c[0] = 0.70710678f * damp; q.c[1] = 0.5f * damp; q.c[2] = 0.35355339f * damp;
  return q;
}
inline float3 conn_min_b(float3 b, float3 vi, float k, float kl, float c, float mask, float3 uj, float3 vj, float3 f) {
  const float3 r = uj + b;  // b = h·d − ui
  const float len_sq = dot(r, r);
  const float inv = rsqrt(fmax(len_sq, 1e-30f));
  const float s = mask * fma(c * dot(vj - vi, r), inv * inv, fma(-kl, inv, k));
  return fma((float3)(s), r, f);
}
inline float3 conn_min(float3 ui, float3 vi, float k, float kl, float c, float mask, float3 uj, float3 vj, int dx, int dy,
                       int dz, float h, float3 f) {
  const float3 r = (float3)(h * dx, h * dy, h * dz) + (uj - ui);
  const float len_sq = dot(r, r);
  const float inv = rsqrt(fmax(len_sq, 1e-30f));
  const float s = mask * fma(c * dot(vj - vi, r), inv * inv, fma(-kl, inv, k));
  return fma((float3)(s), r, f);
}

#if ORDER < 4
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
#if MIN
  const Coef co = coef_of(h * Ei, damping_e, h);
  const float bx[3] = {-h - ui.x, -ui.x, h - ui.x}, by[3] = {-h - ui.y, -ui.y, h - ui.y}, bz[3] = {-h - ui.z, -ui.z, h - ui.z};
#define BD(d) ((float3)(bx[DX[d] + 1], by[DY[d] + 1], bz[DZ[d] + 1]))
#endif
  float3 f = (float3)(0);
#if MIN == 2  // elements whose 26 neighbours are all present: no masks, no selects (the cube's interior here;
              // main would mark them)
  const uint ex = e % NC, ey = (e / NC) % NC, ez = e / (NC * NC);
  if (ex > 0 && ex < NC - 1 && ey > 0 && ey < NC - 1 && ez > 0 && ez < NC - 1) {
#pragma unroll
    for (int d = 0; d < 26; ++d) {
      const int j = grid[cell + DX[d] + sy * DY[d] + sz * DZ[d]];
      const int m = ABS1(DX[d]) + ABS1(DY[d]) + ABS1(DZ[d]) - 1;
      f = conn_min_b(BD(d), vi, co.k[m], co.kl[m], co.c[m], 1.0f, load_u(LSRC, src, j, n), load_v(LSRC, src, j, n), f);
    }
  } else
#endif
#pragma unroll
  for (int d = 0; d < 26; ++d) {
    const int jn = grid[cell + DX[d] + sy * DY[d] + sz * DZ[d]];
    const float present = jn >= 0 ? 1.0f : 0.0f;
    const int j = jn >= 0 ? jn : (int)e;
    const float3 uj = load_u(LSRC, src, j, n);
#if MIN
    {
      const int m = ABS1(DX[d]) + ABS1(DY[d]) + ABS1(DZ[d]) - 1;
      f = conn_min_b(BD(d), vi, co.k[m], co.kl[m], co.c[m], present, uj, load_v(LSRC, src, j, n), f);
    }
    continue;
#endif
#if LEAN
    f += conn_lean(ui, vi, present * (kap(d) * h * Ei), present * (damping_e * skap(d)), uj, load_v(LSRC, src, j, n),
                   DX[d], DY[d], DZ[d], h);
    continue;
#endif
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

#endif

#if ORDER >= 4
#ifndef RESTRICT
#define RESTRICT
#endif
// A cell's state for the march: the element at padded cell c (present 0 where none; element 0's
// state read in its place, a hot line).
inline float cell_state(global const float* src, global const int* grid, int c, uint n, float3* u, float3* v) {
  const int jn = grid[c];
  const int j = jn >= 0 ? jn : 0;
  *u = load_u(LSRC, src, j, n);
  *v = load_v(LSRC, src, j, n);
  return jn >= 0 ? 1.0f : 0.0f;
}
// The force on a centre (ui, vi; its spring factor h·E and dashpot coefficient) from a neighbour
// (uj, vj, present) at lattice offset (dx, dy, dz): the gather's connection, term for term.
inline float3 conn(float3 ui, float3 vi, float hE, float damp, float3 uj, float3 vj, float present, int dx, int dy,
                   int dz, float h) {
  const int m = ABS1(dx) + ABS1(dy) + ABS1(dz);
  const float kp = m == 1 ? 0.5f : m == 2 ? 0.25f : 0.125f;
  const float sk = m == 1 ? 0.70710678f : m == 2 ? 0.5f : 0.35355339f;
  const float dl = m == 1 ? 1.0f : m == 2 ? 1.41421356f : 1.73205081f;
  const float3 r = (float3)(h * dx, h * dy, h * dz) + (uj - ui);
  const float len_sq = dot(r, r);
  const float inv = len_sq > 0 ? rsqrt(len_sq) : 0.0f;
  const float3 nn = r * inv;
  float mag = present * (kp * hE) * (len_sq * inv - h * dl);
  mag += present * (damp * sk) * dot(vj - vi, nn);
  return mag * nn;
}
// One centre of the march: its element (-1: none), state, inverse mass, h·E, dashpot, force.
typedef struct { int e; float3 u, v, f; float w, hE, damp; } Centre;
inline Centre centre_load(global const float* src, global const float* W, global const float* E,
                          global const int* grid, int c, uint n, float h, float zeta, int own) {
  Centre k;
  const int jn = grid[c];
  k.e = jn;
  const int j = jn >= 0 ? jn : 0;
  k.u = load_u(LSRC, src, j, n);
  k.v = load_v(LSRC, src, j, n);
  k.f = (float3)(0);
  k.w = 0; k.hE = 0; k.damp = 0;
  if (own && jn >= 0) {  // a centre the work-item steps (not a halo plane's)
    k.w = W[j];
    k.hE = h * E[j];
    k.damp = 2 * zeta * sqrt(h * E[j] / (2 * k.w));
  }
  return k;
}
inline void centre_store(Centre k, global const float* base, global float* out, uint n, float dt, int second) {
  const uint e = (uint)k.e;
  float3 a = k.f * k.w - k.v;
  a.z -= 9.81f;
  if (k.w == 0) {
    if (!second) store(LOUT, out, e, n, k.u, k.v);
    else store(LOUT, out, e, n, load_u(LBASE, base, e, n), load_v(LBASE, base, e, n));
  } else if (!second) {
    store(LOUT, out, e, n, k.u + dt * k.v, k.v + dt * a);
  } else {
    const float3 ub = load_u(LBASE, base, e, n), vb = load_v(LBASE, base, e, n);
    store(LOUT, out, e, n, ub + 0.5f * dt * (vb + k.v), 0.5f * (vb + k.v) + 0.5f * dt * a);
  }
}

// centre_load without branches: W and E read for halo centres too (ORDERs 5-7)
inline Centre centre_load2(global const float* RESTRICT src, global const float* RESTRICT W, global const float* RESTRICT E,
                           global const int* RESTRICT grid, int c, uint n, float h, float zeta) {
  Centre k;
  const int jn = grid[c];
  k.e = jn;
  const int j = jn >= 0 ? jn : 0;
  k.u = load_u(LSRC, src, j, n);
  k.v = load_v(LSRC, src, j, n);
  k.f = (float3)(0);
  k.w = W[j];
  k.hE = h * E[j];
  k.damp = 2 * zeta * sqrt(h * E[j] / (2 * k.w));
  return k;
}
// A work-item per column piece: (x, y) and the TZ cells from z0 = TZ·b, consecutive work-items
// along x (a warp's reads as contiguous as the gather's). It walks the planes p = z0 - 1 … z0 + TZ;
// plane p's 9 cells serve the centres at p - 1 (offset dz = +1), p (dz = 0) and p + 1 (dz = -1),
// so the ring holds three centres; the centre at p - 1 is complete after plane p and is stored.
#if ORDER == 4
kernel void stage(global const float* src, global const float* base, global float* out, global const float* W,
                  global const float* E, global const int* grid, global const uint* cell_of, global const uint* L,
                  int sy, int sz, float h, float dt, float zeta, int second, uint n) {
  const uint gid = get_global_id(0);
  const uint x = gid % NC, y = (gid / NC) % NC, b = gid / (NC * NC);
  const int z0 = (int)(b * TZ);
  if (z0 >= (int)NC) return;
  const int zend = min((int)NC, z0 + (int)TZ);  // one past the piece's last cell
  const int col = (int)(x + 1) + sy * (int)(y + 1) + sz;  // padded cell of (x, y, 0); plane p adds sz·p
  Centre prv;  // the centre at p - 1 (unused at k = 0)
  prv.e = -1; prv.u = prv.v = prv.f = (float3)(0); prv.w = prv.hE = prv.damp = 0;
  Centre cur = centre_load(src, W, E, grid, col + sz * (z0 - 1), n, h, zeta, 0);
#pragma unroll
  for (int k = 0; k < (int)TZ + 2; ++k) {
    const int p = z0 - 1 + k;
    if (p > zend) break;
    // the centre at p + 1: stepped if inside the piece, else (p + 1 = zend) only a neighbour
    Centre nxt;
    if (p + 1 <= zend) nxt = centre_load(src, W, E, grid, col + sz * (p + 1), n, h, zeta, p + 1 < zend);
    else { nxt.e = -1; nxt.u = nxt.v = nxt.f = (float3)(0); nxt.w = nxt.hE = nxt.damp = 0; }
    const int do_prv = k >= 2 && p - 1 < zend && prv.e >= 0;
    const int do_cur = k >= 1 && p < zend && cur.e >= 0;
    const int do_nxt = p + 1 < zend && nxt.e >= 0;
    const float cur_present = cur.e >= 0 ? 1.0f : 0.0f;
#pragma unroll
    for (int dy = -1; dy <= 1; ++dy)
#pragma unroll
      for (int dx = -1; dx <= 1; ++dx) {
        float3 uq, vq;
        float pq;
        if (dx == 0 && dy == 0) { uq = cur.u; vq = cur.v; pq = cur_present; }
        else pq = cell_state(src, grid, col + dx + sy * dy + sz * p, n, &uq, &vq);
        if (do_prv) prv.f += conn(prv.u, prv.v, prv.hE, prv.damp, uq, vq, pq, dx, dy, 1, h);
        if (do_cur && (dx != 0 || dy != 0)) cur.f += conn(cur.u, cur.v, cur.hE, cur.damp, uq, vq, pq, dx, dy, 0, h);
        if (do_nxt) nxt.f += conn(nxt.u, nxt.v, nxt.hE, nxt.damp, uq, vq, pq, dx, dy, -1, h);
      }
    if (do_prv) centre_store(prv, base, out, n, dt, second);
    prv = cur;
    cur = nxt;
  }
}
#endif

#if ORDER == 5
// ORDER 5: the march without branches in the plane's work (attempt 36b): a plane's 8 side cells
// read first (grid entries, then states), every centre's three connections evaluated and masked
// by multiplication, planes past the piece's end read at its last plane and masked; only the
// store branches. RESTRICT (PROTO_OPTS -DRESTRICT=restrict) lets the compiler hoist the next
// plane's reads above a store.
kernel void stage(global const float* RESTRICT src, global const float* RESTRICT base, global float* RESTRICT out,
                  global const float* RESTRICT W, global const float* RESTRICT E, global const int* RESTRICT grid,
                  global const uint* cell_of, global const uint* L, int sy, int sz, float h, float dt, float zeta,
                  int second, uint n) {
  const uint gid = get_global_id(0);
  const uint x = gid % NC, y = (gid / NC) % NC, b = gid / (NC * NC);
  const int z0 = (int)(b * TZ);
  if (z0 >= (int)NC) return;
  const int zend = min((int)NC, z0 + (int)TZ);
  const int col = (int)(x + 1) + sy * (int)(y + 1) + sz;
  Centre prv = centre_load2(src, W, E, grid, col + sz * (z0 - 1), n, h, zeta);  // unused at k < 2
  Centre cur = prv;
#pragma unroll
  for (int k = 0; k < (int)TZ + 2; ++k) {
    const int p = z0 - 1 + k;
    const int pl = min(p, zend);  // the plane read (past the end: masked)
    Centre nxt = centre_load2(src, W, E, grid, col + sz * min(p + 1, zend), n, h, zeta);
    const float mp = (k >= 2 && p - 1 < zend && prv.e >= 0) ? 1.0f : 0.0f;
    const float mc = (k >= 1 && p < zend && cur.e >= 0) ? 1.0f : 0.0f;
    const float mn = (p + 1 < zend && nxt.e >= 0) ? 1.0f : 0.0f;
    int jq[9];
    float3 uq[9], vq[9];
    float pq[9];
#pragma unroll
    for (int q = 0; q < 9; ++q) {
      const int dx = q % 3 - 1, dy = q / 3 - 1;
      if (q != 4) jq[q] = grid[col + dx + sy * dy + sz * pl];
    }
#pragma unroll
    for (int q = 0; q < 9; ++q) {
      if (q == 4) { uq[q] = cur.u; vq[q] = cur.v; pq[q] = cur.e >= 0 ? 1.0f : 0.0f; continue; }
      const int j = jq[q] >= 0 ? jq[q] : 0;
      uq[q] = load_u(LSRC, src, j, n);
      vq[q] = load_v(LSRC, src, j, n);
      pq[q] = jq[q] >= 0 ? 1.0f : 0.0f;
    }
#pragma unroll
    for (int q = 0; q < 9; ++q) {
      const int dx = q % 3 - 1, dy = q / 3 - 1;
#if LEAN  // the masks folded into the two coefficients
      {
        const int m1 = ABS1(dx) + ABS1(dy) + 1, m0 = ABS1(dx) + ABS1(dy);
        const float k1 = m1 == 1 ? 0.5f : m1 == 2 ? 0.25f : 0.125f, s1 = m1 == 1 ? 0.70710678f : m1 == 2 ? 0.5f : 0.35355339f;
        const float k0 = m0 == 1 ? 0.5f : 0.25f, s0 = m0 == 1 ? 0.70710678f : 0.5f;
        if (k >= 2) prv.f += conn_lean(prv.u, prv.v, mp * pq[q] * k1 * prv.hE, mp * pq[q] * s1 * prv.damp, uq[q], vq[q], dx, dy, 1, h);
        if (k >= 1 && q != 4) cur.f += conn_lean(cur.u, cur.v, mc * pq[q] * k0 * cur.hE, mc * pq[q] * s0 * cur.damp, uq[q], vq[q], dx, dy, 0, h);
        if (k < (int)TZ + 1) nxt.f += conn_lean(nxt.u, nxt.v, mn * pq[q] * k1 * nxt.hE, mn * pq[q] * s1 * nxt.damp, uq[q], vq[q], dx, dy, -1, h);
      }
#else
      if (k >= 2) prv.f += mp * conn(prv.u, prv.v, prv.hE, prv.damp, uq[q], vq[q], pq[q], dx, dy, 1, h);
      if (k >= 1 && q != 4) cur.f += mc * conn(cur.u, cur.v, cur.hE, cur.damp, uq[q], vq[q], pq[q], dx, dy, 0, h);
      if (k < (int)TZ + 1) nxt.f += mn * conn(nxt.u, nxt.v, nxt.hE, nxt.damp, uq[q], vq[q], pq[q], dx, dy, -1, h);
#endif
    }
    if (k >= 2 && mp != 0) centre_store(prv, base, out, n, dt, second);
    prv = cur;
    cur = nxt;
  }
}
#endif

#if ORDER == 6
// ORDER 6 (attempt 36e, an upper bound, not a form main could take as it is): the lean march with
// every index computed, no grid read, as the harness's cube numbers its elements in grid order
// (e = x + NC (y + NC z)); a cell outside the cube reads its clamped neighbour and is masked.
kernel void stage(global const float* RESTRICT src, global const float* RESTRICT base, global float* RESTRICT out,
                  global const float* RESTRICT W, global const float* RESTRICT E, global const int* RESTRICT grid,
                  global const uint* cell_of, global const uint* L, int sy, int sz, float h, float dt, float zeta,
                  int second, uint n) {
  const uint gid = get_global_id(0);
  const int x = (int)(gid % NC), y = (int)((gid / NC) % NC), b = (int)(gid / (NC * NC));
  const int z0 = b * (int)TZ;
  if (z0 >= (int)NC) return;
  const int zend = min((int)NC, z0 + (int)TZ);
  const int row = x + (int)NC * y;  // the column's index in a plane
  Centre prv, cur;
  {
    const int zc = max(z0 - 1, 0);
    const int j = row + (int)(NC * NC) * zc;
    cur.e = z0 >= 1 ? j : -1;
    cur.u = load_u(LSRC, src, j, n); cur.v = load_v(LSRC, src, j, n); cur.f = (float3)(0);
    cur.w = W[j]; cur.hE = h * E[j]; cur.damp = 2 * zeta * sqrt(h * E[j] / (2 * cur.w));
  }
  prv = cur;
#pragma unroll
  for (int k = 0; k < (int)TZ + 2; ++k) {
    const int p = z0 - 1 + k;
    const int pl = clamp(p, 0, min(zend, (int)NC - 1));  // the plane read (outside the cube or past the halo: masked)
    const float plane_in = (p >= 0 && p <= zend && p < (int)NC) ? 1.0f : 0.0f;
    Centre nxt;
    {
      const int zn = min(p + 1, zend - 1 + (zend < (int)NC ? 1 : 0));
      const int j = row + (int)(NC * NC) * zn;
      nxt.e = (p + 1 < (int)NC) ? j : -1;
      nxt.u = load_u(LSRC, src, j, n); nxt.v = load_v(LSRC, src, j, n); nxt.f = (float3)(0);
      nxt.w = W[j]; nxt.hE = h * E[j]; nxt.damp = 2 * zeta * sqrt(h * E[j] / (2 * nxt.w));
    }
    const float mp = (k >= 2 && p - 1 < zend && prv.e >= 0) ? 1.0f : 0.0f;
    const float mc = (k >= 1 && p < zend && cur.e >= 0) ? 1.0f : 0.0f;
    const float mn = (p + 1 < zend && nxt.e >= 0) ? 1.0f : 0.0f;
    float3 uq[9], vq[9];
    float pq[9];
#pragma unroll
    for (int q = 0; q < 9; ++q) {
      const int dx = q % 3 - 1, dy = q / 3 - 1;
      if (q == 4) { uq[q] = cur.u; vq[q] = cur.v; pq[q] = cur.e >= 0 ? 1.0f : 0.0f; continue; }
      const int xn = x + dx, yn = y + dy;
      const int inside = xn >= 0 && xn < (int)NC && yn >= 0 && yn < (int)NC;
      const int j = (inside ? row + dx + (int)NC * dy : row) + (int)(NC * NC) * pl;
      uq[q] = load_u(LSRC, src, j, n);
      vq[q] = load_v(LSRC, src, j, n);
      pq[q] = inside ? plane_in : 0.0f;
    }
#pragma unroll
    for (int q = 0; q < 9; ++q) {
      const int dx = q % 3 - 1, dy = q / 3 - 1;
      const int m1 = ABS1(dx) + ABS1(dy) + 1, m0 = ABS1(dx) + ABS1(dy);
      const float k1 = m1 == 1 ? 0.5f : m1 == 2 ? 0.25f : 0.125f, s1 = m1 == 1 ? 0.70710678f : m1 == 2 ? 0.5f : 0.35355339f;
      const float k0 = m0 == 1 ? 0.5f : 0.25f, s0 = m0 == 1 ? 0.70710678f : 0.5f;
      if (k >= 2) prv.f += conn_lean(prv.u, prv.v, mp * pq[q] * k1 * prv.hE, mp * pq[q] * s1 * prv.damp, uq[q], vq[q], dx, dy, 1, h);
      if (k >= 1 && q != 4) cur.f += conn_lean(cur.u, cur.v, mc * pq[q] * k0 * cur.hE, mc * pq[q] * s0 * cur.damp, uq[q], vq[q], dx, dy, 0, h);
      if (k < (int)TZ + 1) nxt.f += conn_lean(nxt.u, nxt.v, mn * pq[q] * k1 * nxt.hE, mn * pq[q] * s1 * nxt.damp, uq[q], vq[q], dx, dy, -1, h);
    }
    if (k >= 2 && mp != 0) centre_store(prv, base, out, n, dt, second);
    prv = cur;
    cur = nxt;
  }
}
#endif

#if ORDER == 7
// ORDER 7 (attempt 36f): the lean march over the grid with two adjacent work-items per column
// piece, so each holds half a plane's cells: the first takes the cells (dx, dy) = (-1..1, -1) and
// (-1, 0), the second their mirror images (dx, dy) → (-dx, -dy); the centre cell's connection to
// the centre below goes to the first, to the one above to the second. Each keeps the three
// centres and a partial force; the stored centre's force is the pair's sum (NV_SHFL: a butterfly
// shuffle; elsewhere through local memory). Why: ORDER 5 ran latency-bound at 96-110 registers.
#ifdef NV_SHFL
inline float xor1(float x) {
  float r;
  asm volatile("shfl.sync.bfly.b32 %0, %1, 1, 0x1f, 0xffffffff;" : "=f"(r) : "f"(x));
  return r;
}
#endif
// conn_lean with the rest vector given (h·d, mirrored for the second work-item)
inline float3 conn_hd(float3 ui, float3 vi, float kE, float cD, float3 uj, float3 vj, float3 hd, float hdl) {
  const float3 r = hd + (uj - ui);
  const float len_sq = dot(r, r);
  const float inv = rsqrt(fmax(len_sq, 1e-30f));
  const float s = kE * (len_sq * inv - hdl) + cD * dot(vj - vi, r) * inv;
  return (s * inv) * r;
}
kernel void stage(global const float* RESTRICT src, global const float* RESTRICT base, global float* RESTRICT out,
                  global const float* RESTRICT W, global const float* RESTRICT E, global const int* RESTRICT grid,
                  global const uint* cell_of, global const uint* L, int sy, int sz, float h, float dt, float zeta,
                  int second, uint n) {
  const uint gid = get_global_id(0);
  const uint c = gid >> 1;
  const int second_item = (int)(gid & 1);
  const int si = second_item ? -1 : 1;
  const float sgh = second_item ? -h : h;
  const uint x = c % NC, y = (c / NC) % NC;
  uint b = c / (NC * NC);
  const int active = b * TZ < NC;  // padding work-items run a valid piece and store nothing
  if (!active) b = (NC - 1) / TZ;
  const int z0 = (int)(b * TZ);
  const int zend = min((int)NC, z0 + (int)TZ);
  const int col = (int)(x + 1) + sy * (int)(y + 1) + sz;
#ifndef NV_SHFL
  local float xch[3 * 1024];
  const uint lid = get_local_id(0);
#endif
  Centre prv = centre_load2(src, W, E, grid, col + sz * (z0 - 1), n, h, zeta);
  Centre cur = prv;
#pragma unroll
  for (int k = 0; k < (int)TZ + 2; ++k) {
    const int p = z0 - 1 + k;
    const int pl = min(p, zend);
    Centre nxt = centre_load2(src, W, E, grid, col + sz * min(p + 1, zend), n, h, zeta);
    const float mp = (k >= 2 && p - 1 < zend && prv.e >= 0) ? 1.0f : 0.0f;
    const float mc = (k >= 1 && p < zend && cur.e >= 0) ? 1.0f : 0.0f;
    const float mn = (p + 1 < zend && nxt.e >= 0) ? 1.0f : 0.0f;
    int jq[4];
    float3 uq[4], vq[4];
    float pq[4];
#pragma unroll
    for (int q = 0; q < 4; ++q) {
      const int bdx = q < 3 ? q - 1 : -1, bdy = q < 3 ? -1 : 0;
      jq[q] = grid[col + si * (bdx + sy * bdy) + sz * pl];
    }
#pragma unroll
    for (int q = 0; q < 4; ++q) {
      const int j = jq[q] >= 0 ? jq[q] : 0;
      uq[q] = load_u(LSRC, src, j, n);
      vq[q] = load_v(LSRC, src, j, n);
      pq[q] = jq[q] >= 0 ? 1.0f : 0.0f;
    }
#pragma unroll
    for (int q = 0; q < 4; ++q) {
      const int bdx = q < 3 ? q - 1 : -1, bdy = q < 3 ? -1 : 0;
      const int m0 = ABS1(bdx) + ABS1(bdy), m1 = m0 + 1;
      const float k1 = m1 == 1 ? 0.5f : m1 == 2 ? 0.25f : 0.125f, s1 = m1 == 1 ? 0.70710678f : m1 == 2 ? 0.5f : 0.35355339f;
      const float l1 = m1 == 1 ? 1.0f : m1 == 2 ? 1.41421356f : 1.73205081f;
      const float k0 = m0 == 1 ? 0.5f : 0.25f, s0 = m0 == 1 ? 0.70710678f : 0.5f, l0 = m0 == 1 ? 1.0f : 1.41421356f;
      const float hx = sgh * bdx, hy = sgh * bdy;
      if (k >= 2)
        prv.f += conn_hd(prv.u, prv.v, mp * pq[q] * k1 * prv.hE, mp * pq[q] * s1 * prv.damp, uq[q], vq[q],
                         (float3)(hx, hy, h), h * l1);
      if (k >= 1)
        cur.f += conn_hd(cur.u, cur.v, mc * pq[q] * k0 * cur.hE, mc * pq[q] * s0 * cur.damp, uq[q], vq[q],
                         (float3)(hx, hy, 0), h * l0);
      if (k < (int)TZ + 1)
        nxt.f += conn_hd(nxt.u, nxt.v, mn * pq[q] * k1 * nxt.hE, mn * pq[q] * s1 * nxt.damp, uq[q], vq[q],
                         (float3)(hx, hy, -h), h * l1);
    }
    {  // the centre cell: to the centre below (first work-item) or above (second)
      const float cp = cur.e >= 0 ? 1.0f : 0.0f;
      const float mt = second_item ? (k < (int)TZ + 1 ? mn : 0.0f) : (k >= 2 ? mp : 0.0f);
      const float3 tu = second_item ? nxt.u : prv.u, tv = second_item ? nxt.v : prv.v;
      const float thE = second_item ? nxt.hE : prv.hE, tdamp = second_item ? nxt.damp : prv.damp;
      const float3 g = conn_hd(tu, tv, mt * cp * 0.5f * thE, mt * cp * 0.70710678f * tdamp, cur.u, cur.v,
                               (float3)(0, 0, second_item ? -h : h), h);
      if (second_item) nxt.f += g; else prv.f += g;
    }
    if (k >= 2) {  // the pair's sum of the completed centre's force
#ifdef NV_SHFL
      const float3 other = (float3)(xor1(prv.f.x), xor1(prv.f.y), xor1(prv.f.z));
#else
      barrier(CLK_LOCAL_MEM_FENCE);
      xch[3 * lid] = prv.f.x; xch[3 * lid + 1] = prv.f.y; xch[3 * lid + 2] = prv.f.z;
      barrier(CLK_LOCAL_MEM_FENCE);
      const uint o = lid ^ 1u;
      const float3 other = (float3)(xch[3 * o], xch[3 * o + 1], xch[3 * o + 2]);
#endif
      prv.f += other;
      if (active && !second_item && mp != 0) centre_store(prv, base, out, n, dt, second);
    }
    prv = cur;
    cur = nxt;
  }
}
#endif
#if ORDER == 8
// ORDER 8 (attempt 37): the column piece's TZ centres all held at once and the 9 neighbouring
// columns visited one after the other, each column's TZ + 2 cells read once and handed to the (at
// most three) centres they touch. The same reads as the plane march (9 (TZ + 2) / TZ per element)
// and the same connections (26 per centre, none masked away), but only the centres and one
// column live in registers, not a ring of three centres and a plane of nine cells. Lean
// connection only. Summation per centre: column by column, then dz.
kernel void stage(global const float* RESTRICT src, global const float* RESTRICT base, global float* RESTRICT out,
                  global const float* RESTRICT W, global const float* RESTRICT E, global const int* RESTRICT grid,
                  global const uint* cell_of, global const uint* L, int sy, int sz, float h, float dt, float zeta,
                  int second, uint n) {
  const uint pieces = NC * NC * ((NC + TZ - 1) / TZ);
#if REVERSE  // the pieces from the last to the first (PROTO_REVERSE: the second stage)
  if (get_global_id(0) >= pieces) return;
  const uint gid = pieces - 1 - get_global_id(0);
#else
  const uint gid = get_global_id(0);
#endif
  const uint x = gid % NC, y = (gid / NC) % NC, b = gid / (NC * NC);
  const int z0 = (int)(b * TZ);
  if (z0 >= (int)NC) return;
  const int zend = min((int)NC, z0 + (int)TZ);
  const int col = (int)(x + 1) + sy * (int)(y + 1) + sz;  // padded cell of (x, y, 0); plane p adds sz·p
  Centre c[TZ];
  float mc[TZ];  // 1 for a centre this work-item steps
#pragma unroll
  for (int t = 0; t < (int)TZ; ++t) {
    c[t] = centre_load2(src, W, E, grid, col + sz * min(z0 + t, zend), n, h, zeta);  // past the end: the halo cell
    mc[t] = (z0 + t < zend && c[t].e >= 0) ? 1.0f : 0.0f;
  }
#if MIN == 3  // one set of coefficients per piece, from its first free centre (the harness's free
              // elements share E and w; a held centre's force is never used)
  float hE_p = c[TZ - 1].hE, damp_p = c[TZ - 1].damp;
#pragma unroll
  for (int t = (int)TZ - 2; t >= 0; --t)
    if (c[t].w != 0) { hE_p = c[t].hE; damp_p = c[t].damp; }
  const Coef cp = coef_of(hE_p, damp_p, h);
#define CO(t) cp
#elif MIN
  Coef co[TZ];
#pragma unroll
  for (int t = 0; t < (int)TZ; ++t) co[t] = coef_of(c[t].hE, c[t].damp, h);
#define CO(t) co[t]
#endif
#pragma unroll
  for (int q = 0; q < 9; ++q) {
    const int dx = q % 3 - 1, dy = q / 3 - 1;
#pragma unroll
    for (int s = 0; s < (int)TZ + 2; ++s) {
      const int p = min(z0 - 1 + s, zend);  // the plane read (past the halo: feeds only masked centres)
      float3 uq, vq;
      float pq;
      if (q == 4 && s >= 1 && s <= (int)TZ) {
        uq = c[s - 1].u; vq = c[s - 1].v; pq = c[s - 1].e >= 0 ? 1.0f : 0.0f;
      } else {
        const int jn = grid[col + dx + sy * dy + sz * p];
        const int j = jn >= 0 ? jn : 0;
        uq = load_u(LSRC, src, j, n); vq = load_v(LSRC, src, j, n);
        pq = jn >= 0 ? 1.0f : 0.0f;
      }
#pragma unroll
      for (int t = max(0, s - 2); t <= min((int)TZ - 1, s); ++t) {
        const int dz = s - 1 - t;
        if (q == 4 && dz == 0) continue;  // the centre itself
        const int m = ABS1(dx) + ABS1(dy) + ABS1(dz);
#if MIN
        c[t].f = conn_min(c[t].u, c[t].v, CO(t).k[m - 1], CO(t).kl[m - 1], CO(t).c[m - 1], mc[t] * pq, uq, vq, dx, dy, dz, h, c[t].f);
        continue;
#endif
        const float kp = m == 1 ? 0.5f : m == 2 ? 0.25f : 0.125f, sk = m == 1 ? 0.70710678f : m == 2 ? 0.5f : 0.35355339f;
        c[t].f += conn_lean(c[t].u, c[t].v, mc[t] * pq * kp * c[t].hE, mc[t] * pq * sk * c[t].damp, uq, vq, dx, dy, dz, h);
      }
    }
  }
#pragma unroll
  for (int t = 0; t < (int)TZ; ++t)
    if (mc[t] != 0) centre_store(c[t], base, out, n, dt, second);
}
#endif
#endif

kernel void copy4(global const float4* a, global float4* b) { b[get_global_id(0)] = a[get_global_id(0)]; }
