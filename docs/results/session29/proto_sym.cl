// Session 29 prototype (docs/PERF_NOTES.md, attempt 38; not part of the build): session 28's
// proto_march.cl with ORDER 9 added at the end (each connection once), run by session 29's
// proto_sym.cpp. Session 28's header: session 27's proto_march.cl with ORDER 8 added (the march in column order, at the end) and MIN, the
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
#if ORDER == 9 || ORDER == 10
// ORDER 9 (session 29, attempt 38): each connection evaluated once, for both of its ends. A
// work-group is a tile of 32 x TY columns (a warp per row along x) marching up a piece of TZ
// planes; each element evaluates the 13 connections of the half-stencil H (dy = +1: 9; dy = 0,
// dz = +1: 3; (1, 0, 0)), adds them to its own force and hands the opposite force to the other
// end: along x by warp shuffles (summed per target column first), to the next row through local
// memory, to the next plane in its own registers. Every d in H has dy >= 0, so only the tile's
// first row is a halo (it evaluates H for the row above it, its own force is not used); along x
// lanes 0 and 31 are halos (owned columns 30 per warp), along z the planes z0 - 1 and z0 + TZ.
// The neighbours' states come from a ring of four planes in local memory (the tile's rows and
// one more, loaded by the halo row). One barrier per plane. Needs a uniform material (the
// connection's coefficients from its source end) and is checked against ORDER 0 with every
// element free (PROTO_NOHELD=1). NV=1: shuffles as PTX (shfl.sync); else through local memory
// with barriers (PoCL, for the check).
#define SROW 32
#define WGS (SROW * TY)
#define NCELL (SROW * (TY + 1) + 1)
#if NV
inline float shfl_up1(float x) {  // lane l gets lane l - 1's x; lane 0 its own
  uint r;
  asm volatile("shfl.sync.up.b32 %0, %1, 1, 0x0, 0xffffffff;" : "=r"(r) : "r"(as_uint(x)));
  return as_float(r);
}
inline float shfl_down1(float x) {  // lane l gets lane l + 1's x; lane 31 its own
  uint r;
  asm volatile("shfl.sync.down.b32 %0, %1, 1, 0x1f, 0xffffffff;" : "=r"(r) : "r"(as_uint(x)));
  return as_float(r);
}
#define SHUP(a) ((float3)(shfl_up1((a).x), shfl_up1((a).y), shfl_up1((a).z)))
#define SHDN(a) ((float3)(shfl_down1((a).x), shfl_down1((a).y), shfl_down1((a).z)))
#else
inline float3 sh_move(local float4* sh, float3 a, uint lid, uint lx, int up) {
  barrier(CLK_LOCAL_MEM_FENCE);
  sh[lid] = (float4)(a, 0);
  barrier(CLK_LOCAL_MEM_FENCE);
  const uint from = up ? (lx > 0 ? lid - 1 : lid) : (lx < SROW - 1 ? lid + 1 : lid);
  return sh[from].xyz;
}
#define SHUP(a) sh_move(shx, (a), lid, lx, 1)
#define SHDN(a) sh_move(shx, (a), lid, lx, 0)
#endif
// The padded cell of (x, y, p) or -1 outside the padded grid (the tile's halos may reach past it).
inline int cell_at(int x, int y, int p, int sy, int sz) {
  if (x < -1 || x > (int)NC || y < -1 || y > (int)NC || p < -1 || p > (int)NC) return -1;
  return (x + 1) + sy * (y + 1) + sz * (p + 1);
}
// One connection of the half-stencil from the source (ui, vi; coefficients q of its class m) to
// the neighbour at local index li of ring slot sl: the force on the source (its opposite acts on
// the neighbour). mask: the source present.
inline float3 sym_conn(float3 ui, float3 vi, Coef q, int m, float mask, local const float4* sa, local const float2* sb,
                       local const uchar* sp, int li, int dx, int dy, int dz, float h) {
  const float4 a = sa[li];
  const float2 b = sb[li];
  const float3 uj = a.xyz, vj = (float3)(a.w, b.x, b.y);
  return conn_min(ui, vi, q.k[m - 1], q.kl[m - 1], q.c[m - 1], mask * (float)sp[li], uj, vj, dx, dy, dz, h, (float3)(0));
}
#endif
#if ORDER == 9
kernel __attribute__((reqd_work_group_size(WGS, 1, 1)))
void stage(global const float* RESTRICT src, global const float* RESTRICT base, global float* RESTRICT out,
           global const float* RESTRICT W, global const float* RESTRICT E, global const int* RESTRICT grid,
           global const uint* cell_of, global const uint* L, int sy, int sz, float h, float dt, float zeta,
           int second, uint n) {
  local float4 sa[4][NCELL];  // the ring of planes: (u.xyz, v.x)
  local float2 sb[4][NCELL];  // (v.y, v.z)
  local uchar sp[4][NCELL];   // 1 where the cell holds an element
  local float xf[2][3][3][WGS];  // row y's forces for row y + 1's column at planes p - 1, p, p + 1 (x, y, z)
#if !NV
  local float4 shx[WGS];
#endif
  const uint lid = get_local_id(0), lx = lid % SROW, ly = lid / SROW;
  const uint ngx = (NC + SROW - 3) / (SROW - 2), ngy = (NC + TY - 2) / (TY - 1);
  const uint g = get_group_id(0);
  const int x = (int)((g % ngx) * (SROW - 2) + lx) - 1;
  const int y = (int)(((g / ngx) % ngy) * (TY - 1) + ly) - 1;
  const int z0 = (int)((g / (ngx * ngy)) * TZ);
  const int y_top = (int)(((g / ngx) % ngy) * (TY - 1) + TY) - 1;  // the extra row (loaded by row 0)
  const int owned_col = lx >= 1 && lx <= SROW - 2 && ly >= 1 && x < (int)NC && y < (int)NC;
  const int zend = min((int)NC, z0 + (int)TZ);

  // load plane p of this work-item's column (and of the extra row) into the ring
#define LOAD_PLANE(p)                                                                         \
  {                                                                                           \
    const int sl_ = (p) & 3;                                                                  \
    const int c_ = cell_at(x, y, (p), sy, sz);                                                \
    const int jn_ = c_ >= 0 ? grid[c_] : -1;                                                  \
    const int j_ = jn_ >= 0 ? jn_ : 0;                                                        \
    const float3 u_ = load_u(LSRC, src, j_, n), v_ = load_v(LSRC, src, j_, n);                \
    sa[sl_][lid] = (float4)(u_, v_.x);                                                        \
    sb[sl_][lid] = v_.yz;                                                                     \
    sp[sl_][lid] = jn_ >= 0 ? 1 : 0;                                                    \
    nxt_u = u_; nxt_v = v_; nxt_j = jn_;                                                      \
    if (ly == 0) {                                                                            \
      const int ct_ = cell_at(x, y_top, (p), sy, sz);                                         \
      const int jt_ = ct_ >= 0 ? grid[ct_] : -1;                                              \
      const int k_ = jt_ >= 0 ? jt_ : 0;                                                      \
      const float3 ut_ = load_u(LSRC, src, k_, n), vt_ = load_v(LSRC, src, k_, n);            \
      sa[sl_][SROW * TY + lx] = (float4)(ut_, vt_.x);                                         \
      sb[sl_][SROW * TY + lx] = vt_.yz;                                                       \
      sp[sl_][SROW * TY + lx] = jt_ >= 0 ? 1 : 0;                                       \
    }                                                                                         \
  }
  float3 nxt_u, nxt_v;
  int nxt_j;
  LOAD_PLANE(z0 - 1);
  float3 cu = nxt_u, cv = nxt_v;  // the source's (this column at plane p) state
  int cj = nxt_j;
  float3 acc_m2 = (float3)(0), acc_m1 = (float3)(0), acc_0 = (float3)(0), acc_p1 = (float3)(0);
  float3 up_m1 = (float3)(0), up_0 = (float3)(0), up_p1 = (float3)(0);  // forces for row y + 1, planes p-1, p, p+1
  for (int p = z0 - 1; p <= z0 + (int)TZ + 1; ++p) {
    // S1: the next plane into the ring, the last plane's forces for row y + 1 into the exchange
    if (p + 1 <= z0 + (int)TZ) LOAD_PLANE(p + 1);
    {
      const int xs = (p - 1) & 1;
      xf[xs][0][0][lid] = up_m1.x; xf[xs][0][1][lid] = up_m1.y; xf[xs][0][2][lid] = up_m1.z;
      xf[xs][1][0][lid] = up_0.x; xf[xs][1][1][lid] = up_0.y; xf[xs][1][2][lid] = up_0.z;
      xf[xs][2][0][lid] = up_p1.x; xf[xs][2][1][lid] = up_p1.y; xf[xs][2][2][lid] = up_p1.z;
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    // S3: row y - 1's forces from its sources at plane p - 1 on this column's planes p - 2, p - 1, p
    if (ly >= 1 && p > z0 - 1) {
      const int xs = (p - 1) & 1, o = (int)lid - SROW;
      acc_m2 -= (float3)(xf[xs][0][0][o], xf[xs][0][1][o], xf[xs][0][2][o]);
      acc_m1 -= (float3)(xf[xs][1][0][o], xf[xs][1][1][o], xf[xs][1][2][o]);
      acc_0 -= (float3)(xf[xs][2][0][o], xf[xs][2][1][o], xf[xs][2][2][o]);
    }
    // plane p - 2 is complete
    {
      const int q = p - 2;
      if (owned_col && q >= z0 && q < zend) {
        const int c = cell_at(x, y, q, sy, sz);
        const int jn = grid[c];
        if (jn >= 0) {
          Centre k;
          k.e = jn;
          k.u = load_u(LSRC, src, jn, n);
          k.v = load_v(LSRC, src, jn, n);
          k.w = W[jn];
          k.f = acc_m2;
          centre_store(k, base, out, n, dt, second);
        }
      }
    }
    acc_m2 = acc_m1; acc_m1 = acc_0; acc_0 = acc_p1; acc_p1 = (float3)(0);  // now p - 2 .. p + 1 are p - 1 .. p + 2
    up_m1 = up_0 = up_p1 = (float3)(0);
    // S4: the source at plane p (acc_m1 is its own force, acc_0 plane p + 1's). The halo planes
    // evaluate only what reaches the piece (uniform over the work-group): z0 - 1 its connections
    // up to z0, z0 + TZ those down to z0 + TZ - 1.
    if (p <= z0 + (int)TZ) {
      const int inner = p >= z0 && p < z0 + (int)TZ, first = p == z0 - 1, last = p == z0 + (int)TZ;
#if NV  // the halo row's own force and its row's targets are not used (uniform over its warp)
      const int row_used = ly != 0;
#else
      const int row_used = 1;
#endif
      const float ms = cj >= 0 ? 1.0f : 0.0f;
      const float wi = cj >= 0 ? W[cj] : 1.0f, Ei = cj >= 0 ? E[cj] : 0.0f;
      const Coef q = coef_of(h * Ei, 2 * zeta * sqrt(h * Ei / (2 * wi)), h);
      const int s_m = (p - 1) & 3, s_0 = p & 3, s_p = (p + 1) & 3;
      const int li = (int)lid;
      float3 own = (float3)(0);
      // dy = +1: the row above, three columns, three planes; summed per target column by shuffles
#pragma unroll
      for (int dz = -1; dz <= 1; ++dz) {
        if (!(inner || (first && dz == 1) || (last && dz == -1))) continue;
        const int sl = dz < 0 ? s_m : dz == 0 ? s_0 : s_p;
        const float3 fl = sym_conn(cu, cv, q, 2 + ABS1(dz), ms, sa[sl], sb[sl], sp[sl], max(li - 1 + SROW, 0), -1, 1, dz, h);
        const float3 f0 = sym_conn(cu, cv, q, 1 + ABS1(dz), ms, sa[sl], sb[sl], sp[sl], li + SROW, 0, 1, dz, h);
        const float3 fr = sym_conn(cu, cv, q, 2 + ABS1(dz), ms, sa[sl], sb[sl], sp[sl], li + 1 + SROW, 1, 1, dz, h);
        own += fl + f0 + fr;
        // the column above this one receives f0 from here, fr from lane - 1, fl from lane + 1
        const float3 t = f0 + SHUP(fr) + SHDN(fl);
        if (dz < 0) up_m1 = t; else if (dz == 0) up_0 = t; else up_p1 = t;
      }
      // dy = 0, dz = +1: this row's three columns at plane p + 1
      if ((inner || first) && row_used) {
        const float3 fl = sym_conn(cu, cv, q, 2, ms, sa[s_p], sb[s_p], sp[s_p], max(li - 1, 0), -1, 0, 1, h);
        const float3 f0 = sym_conn(cu, cv, q, 1, ms, sa[s_p], sb[s_p], sp[s_p], li, 0, 0, 1, h);
        const float3 fr = sym_conn(cu, cv, q, 2, ms, sa[s_p], sb[s_p], sp[s_p], li + 1, 1, 0, 1, h);
        own += fl + f0 + fr;
        acc_0 -= f0 + SHUP(fr) + SHDN(fl);
      }
      // (1, 0, 0)
      if (inner && row_used) {
        const float3 fr = sym_conn(cu, cv, q, 1, ms, sa[s_0], sb[s_0], sp[s_0], li + 1, 1, 0, 0, h);
        own += fr;
        acc_m1 -= SHUP(fr);
      }
      acc_m1 += own;
    }
    cu = nxt_u; cv = nxt_v; cj = nxt_j;
  }
}
#endif
#if ORDER == 10
// ORDER 10 (session 29, attempt 38b): ORDER 9 with its global reads off the critical path. The
// state, inverse mass and E of plane p + 2 are read during plane p (after its barrier, stored
// into the ring at the next plane's start) and the grid entries of plane p + 3 before them, so
// no plane waits on a global read; the source's own state and inverse mass come from the ring
// (the inverse mass in local memory, -1 where no element, also serves as the presence mask), and
// a plane is stepped after the next plane's connections (the corrector's base read before them).
inline int grid_entry(global const int* grid, int x, int y, int p, int sy, int sz) {
  const int c = cell_at(x, y, p, sy, sz);
  return c >= 0 ? grid[c] : -1;
}
inline float3 sym_conn_w(float3 ui, float3 vi, Coef q, int m, float mask, local const float4* sa, local const float2* sb,
                         local const float* sw, int li, int dx, int dy, int dz, float h) {
  const float4 a = sa[li];
  const float2 b = sb[li];
  const float3 uj = a.xyz, vj = (float3)(a.w, b.x, b.y);
  return conn_min(ui, vi, q.k[m - 1], q.kl[m - 1], q.c[m - 1], sw[li] >= 0 ? mask : 0.0f, uj, vj, dx, dy, dz, h, (float3)(0));
}
kernel __attribute__((reqd_work_group_size(WGS, 1, 1)))
void stage(global const float* RESTRICT src, global const float* RESTRICT base, global float* RESTRICT out,
           global const float* RESTRICT W, global const float* RESTRICT E, global const int* RESTRICT grid,
           global const uint* cell_of, global const uint* L, int sy, int sz, float h, float dt, float zeta,
           int second, uint n) {
  local float4 sa[4][NCELL];  // the ring of planes: (u.xyz, v.x)
  local float2 sb[4][NCELL];  // (v.y, v.z)
  local float sw[4][NCELL];   // inverse mass, -1 where the cell holds no element
  local float xf[2][3][3][WGS];  // row y's forces for row y + 1's column at planes p - 1, p, p + 1
#if !NV
  local float4 shx[WGS];
#endif
  const uint lid = get_local_id(0), lx = lid % SROW, ly = lid / SROW;
  const uint ngx = (NC + SROW - 3) / (SROW - 2), ngy = (NC + TY - 2) / (TY - 1);
  const uint g = get_group_id(0);
  const int x = (int)((g % ngx) * (SROW - 2) + lx) - 1;
  const int y = (int)(((g / ngx) % ngy) * (TY - 1) + ly) - 1;
  const int z0 = (int)((g / (ngx * ngy)) * TZ);
  const int y_top = (int)(((g / ngx) % ngy) * (TY - 1) + TY) - 1;  // the extra row (loaded by row 0)
  const int owned_col = lx >= 1 && lx <= SROW - 2 && ly >= 1 && x < (int)NC && y < (int)NC;
  const int zend = min((int)NC, z0 + (int)TZ), zlast = z0 + (int)TZ;
  const int top = SROW * TY + (int)lx;  // the extra row's ring entry (row 0 writes it)
#define FETCH(jn, u, v, w, e)                                  \
  {                                                            \
    const int j_ = (jn) >= 0 ? (jn) : 0;                       \
    u = load_u(LSRC, src, j_, n);                              \
    v = load_v(LSRC, src, j_, n);                              \
    w = (jn) >= 0 ? W[j_] : -1.0f;                             \
    e = E[j_];                                                 \
  }
#define RING_STORE(sl, li, u, v, w) \
  {                                 \
    sa[sl][li] = (float4)(u, v.x);  \
    sb[sl][li] = v.yz;              \
    sw[sl][li] = w;                 \
  }
  // prologue: plane z0 - 1 into the ring, plane z0 prefetched, plane z0 + 1's grid entries read
  float3 pu, pv, tu = (float3)(0), tv = (float3)(0);
  float pw, pE, tw = -1.0f, tE;
  int pj, tj = -1;
  int j_0 = grid_entry(grid, x, y, z0 - 1, sy, sz);
  float E_0;
  FETCH(j_0, pu, pv, pw, E_0);
  RING_STORE((z0 - 1) & 3, lid, pu, pv, pw);
  if (ly == 0) {
    tj = grid_entry(grid, x, y_top, z0 - 1, sy, sz);
    FETCH(tj, tu, tv, tw, tE);
    RING_STORE((z0 - 1) & 3, top, tu, tv, tw);
  }
  pj = grid_entry(grid, x, y, z0, sy, sz);
  FETCH(pj, pu, pv, pw, pE);
  if (ly == 0) {
    tj = grid_entry(grid, x, y_top, z0, sy, sz);
    FETCH(tj, tu, tv, tw, tE);
  }
  int g_pf = grid_entry(grid, x, y, z0 + 1, sy, sz), gt_pf = ly == 0 ? grid_entry(grid, x, y_top, z0 + 1, sy, sz) : -1;
  int j_m2 = -1, j_m1 = -1;
  float3 acc_m2 = (float3)(0), acc_m1 = (float3)(0), acc_0 = (float3)(0), acc_p1 = (float3)(0);
  float3 up_m1 = (float3)(0), up_0 = (float3)(0), up_p1 = (float3)(0);
  for (int p = z0 - 1; p <= zlast + 1; ++p) {
    // S1: the prefetched plane p + 1 into the ring, the last plane's forces for row y + 1 into
    // the exchange
    if (p + 1 <= zlast) {
      RING_STORE((p + 1) & 3, lid, pu, pv, pw);
      if (ly == 0) RING_STORE((p + 1) & 3, top, tu, tv, tw);
    }
    {
      const int xs = (p - 1) & 1;
      xf[xs][0][0][lid] = up_m1.x; xf[xs][0][1][lid] = up_m1.y; xf[xs][0][2][lid] = up_m1.z;
      xf[xs][1][0][lid] = up_0.x; xf[xs][1][1][lid] = up_0.y; xf[xs][1][2][lid] = up_0.z;
      xf[xs][2][0][lid] = up_p1.x; xf[xs][2][1][lid] = up_p1.y; xf[xs][2][2][lid] = up_p1.z;
    }
    const int j_p1 = pj;
    const float E_p1 = pE;
    // the prefetch of plane p + 2 (its grid entries read a plane ago) and plane p + 3's entries
    if (p + 2 <= zlast) {
      pj = g_pf;
      FETCH(pj, pu, pv, pw, pE);
      if (ly == 0) { tj = gt_pf; FETCH(tj, tu, tv, tw, tE); }
      if (p + 3 <= zlast) {
        g_pf = grid_entry(grid, x, y, p + 3, sy, sz);
        if (ly == 0) gt_pf = grid_entry(grid, x, y_top, p + 3, sy, sz);
      }
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    // S3: row y - 1's forces from its sources at plane p - 1 on this column's planes p - 2, p - 1, p
    if (ly >= 1 && p > z0 - 1) {
      const int xs = (p - 1) & 1, o = (int)lid - SROW;
      acc_m2 -= (float3)(xf[xs][0][0][o], xf[xs][0][1][o], xf[xs][0][2][o]);
      acc_m1 -= (float3)(xf[xs][1][0][o], xf[xs][1][1][o], xf[xs][1][2][o]);
      acc_0 -= (float3)(xf[xs][2][0][o], xf[xs][2][1][o], xf[xs][2][2][o]);
    }
    // plane p - 2 is complete: its corrector base read now, used after the connections
    const int q_step = owned_col && p - 2 >= z0 && p - 2 < zend && j_m2 >= 0;
    float3 bu = (float3)(0), bv = (float3)(0);
    if (q_step && second) { bu = load_u(LBASE, base, j_m2, n); bv = load_v(LBASE, base, j_m2, n); }
    up_m1 = up_0 = up_p1 = (float3)(0);
    // S4: the source at plane p (its force acc_0, plane p + 1's acc_p1)
    if (p <= zlast) {
      const int inner = p >= z0 && p < zlast, first = p == z0 - 1, last = p == zlast;
#if NV
      const int row_used = ly != 0;
#else
      const int row_used = 1;
#endif
      const int s_m = (p - 1) & 3, s_0 = p & 3, s_p = (p + 1) & 3;
      const int li = (int)lid;
      const float4 ca = sa[s_0][li];
      const float2 cb = sb[s_0][li];
      const float3 cu = ca.xyz, cv = (float3)(ca.w, cb.x, cb.y);
      const float wi = sw[s_0][li];
      const float ms = wi >= 0 ? 1.0f : 0.0f;
      const float Ei = ms != 0 ? E_0 : 0.0f, wd = wi > 0 ? wi : 1.0f;
      const Coef q = coef_of(h * Ei, 2 * zeta * sqrt(h * Ei / (2 * wd)), h);
      float3 own = (float3)(0);
#pragma unroll
      for (int dz = -1; dz <= 1; ++dz) {
        if (!(inner || (first && dz == 1) || (last && dz == -1))) continue;
        const int sl = dz < 0 ? s_m : dz == 0 ? s_0 : s_p;
        const float3 fl = sym_conn_w(cu, cv, q, 2 + ABS1(dz), ms, sa[sl], sb[sl], sw[sl], max(li - 1 + SROW, 0), -1, 1, dz, h);
        const float3 f0 = sym_conn_w(cu, cv, q, 1 + ABS1(dz), ms, sa[sl], sb[sl], sw[sl], li + SROW, 0, 1, dz, h);
        const float3 fr = sym_conn_w(cu, cv, q, 2 + ABS1(dz), ms, sa[sl], sb[sl], sw[sl], li + 1 + SROW, 1, 1, dz, h);
        own += fl + f0 + fr;
        const float3 t = f0 + SHUP(fr) + SHDN(fl);
        if (dz < 0) up_m1 = t; else if (dz == 0) up_0 = t; else up_p1 = t;
      }
      if ((inner || first) && row_used) {
        const float3 fl = sym_conn_w(cu, cv, q, 2, ms, sa[s_p], sb[s_p], sw[s_p], max(li - 1, 0), -1, 0, 1, h);
        const float3 f0 = sym_conn_w(cu, cv, q, 1, ms, sa[s_p], sb[s_p], sw[s_p], li, 0, 0, 1, h);
        const float3 fr = sym_conn_w(cu, cv, q, 2, ms, sa[s_p], sb[s_p], sw[s_p], li + 1, 1, 0, 1, h);
        own += fl + f0 + fr;
        acc_p1 -= f0 + SHUP(fr) + SHDN(fl);
      }
      if (inner && row_used) {
        const float3 fr = sym_conn_w(cu, cv, q, 1, ms, sa[s_0], sb[s_0], sw[s_0], li + 1, 1, 0, 0, h);
        own += fr;
        acc_0 -= SHUP(fr);
      }
      acc_0 += own;
    }
    // step plane p - 2 (its state from the ring: this work-item's own entry, rewritten only by it)
    if (q_step) {
      const int sq = (p - 2) & 3;
      const float4 a4 = sa[sq][lid];
      const float2 b2 = sb[sq][lid];
      const float3 u = a4.xyz, v = (float3)(a4.w, b2.x, b2.y);
      const float w = sw[sq][lid];
      float3 a = acc_m2 * w - v;
      a.z -= 9.81f;
      const uint e = (uint)j_m2;
      if (w == 0) {
        if (!second) store(LOUT, out, e, n, u, v);
        else store(LOUT, out, e, n, bu, bv);
      } else if (!second) {
        store(LOUT, out, e, n, u + dt * v, v + dt * a);
      } else {
        store(LOUT, out, e, n, bu + 0.5f * dt * (bv + v), 0.5f * (bv + v) + 0.5f * dt * a);
      }
    }
    acc_m2 = acc_m1; acc_m1 = acc_0; acc_0 = acc_p1; acc_p1 = (float3)(0);
    j_m2 = j_m1; j_m1 = j_0; j_0 = j_p1; E_0 = E_p1;
  }
}
#endif
#endif

kernel void copy4(global const float4* a, global float4* b) { b[get_global_id(0)] = a[get_global_id(0)]; }
