// Session 29 prototype (docs/PERF_NOTES.md, attempt 38; not part of the build): ORDERs 9 and 10
// (each connection once), compiled after session 28's proto_march.cl, which defines everything
// they call (the harness concatenates the two: "../session28/proto_march.cl+proto_sym.cl"; the
// device calls ran the same text as one file).
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
