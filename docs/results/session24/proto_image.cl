// Session 24 prototype (docs/PERF_NOTES.md, attempt 28): a Heun stage of linear springs +
// dashpots on the 26-neighbour lattice of a dense N³ cube, its state read through the texture
// path. (a) stage_gather: main's form (session 18's harness: buffers, cell → grid → neighbour);
// (b) stage_buf3d: buffers, a 3-D range, the neighbour's index computed (the work-group shape as
// the only change); (c) stage_img3d: the state in 3-D images (the driver's tiled layout, the
// texture unit's addressing and border); (d) stage_img2d: 2-D images of N × N² texels.
// Timing only. E rides in v.w in every form.
#ifdef IMG3D_WRITES
#pragma OPENCL EXTENSION cl_khr_3d_image_writes : enable
#endif

constant int DX[26] = {-1,0,1,-1,0,1,-1,0,1, -1,0,1,-1,1,-1,0,1, -1,0,1,-1,0,1,-1,0,1};
constant int DY[26] = {-1,-1,-1,0,0,0,1,1,1, -1,-1,-1,0,0,1,1,1, -1,-1,-1,0,0,0,1,1,1};
constant int DZ[26] = {-1,-1,-1,-1,-1,-1,-1,-1,-1, 0,0,0,0,0,0,0,0, 1,1,1,1,1,1,1,1,1};

inline float kap(int d) { int m = abs(DX[d]) + abs(DY[d]) + abs(DZ[d]); return m == 1 ? 0.5f : m == 2 ? 0.25f : 0.125f; }
inline float dlen(int d) { int m = abs(DX[d]) + abs(DY[d]) + abs(DZ[d]); return m == 1 ? 1.0f : m == 2 ? 1.41421356f : 1.73205081f; }

// The connection's force on i, as main's lattice_force (dashpot path); an absent neighbour has
// E = 0 (kE = 0: no spring, no dashpot).
inline float4 connection(float4 ui, float4 vi, float Ei, float4 uj, float4 vj, float Ej, int d, float h,
                         float zeta) {
  const float4 r = (float4)(h * DX[d] + (uj.x - ui.x), h * DY[d] + (uj.y - ui.y), h * DZ[d] + (uj.z - ui.z), 0);
  const float len_sq = r.x * r.x + r.y * r.y + r.z * r.z;
  const float inv_raw = rsqrt(len_sq);
  const float inv = len_sq > 0 ? inv_raw : 0.0f;
  const float len = len_sq * inv;
  const float4 n = r * inv;
  const float w_sum = ui.w + uj.w;
  const float kE = kap(d) * h * (2 * Ei * Ej);
  const float q = 1 / ((Ei + Ej) * w_sum);
  const float k = kE * w_sum * q;
  float mag = k * (len - h * dlen(d));
  mag += 2 * zeta * sqrt(kE * q) * ((vj.x - vi.x) * n.x + (vj.y - vi.y) * n.y + (vj.z - vi.z) * n.z);
  return mag * n;
}

// Heun: stage 1 returns the predicted state; stage 2 the corrected one from the base (ub, vb).
inline void advance(float4 ui, float4 vi, float4 f, float4 ub, float4 vb, float dt, int second, float4* uo,
                    float4* vo) {
  if (ui.w == 0) { *uo = second ? ub : ui; *vo = second ? vb : vi; return; }
  float4 a = f * ui.w - (float4)(vi.xyz, 0);
  a.z -= 9.81f;
  if (!second) {
    *uo = (float4)(ui.xyz + dt * vi.xyz, ui.w);
    *vo = (float4)(vi.xyz + dt * a.xyz, vi.w);
  } else {
    *uo = (float4)(ub.xyz + 0.5f * dt * (vb.xyz + vi.xyz), ub.w);
    *vo = (float4)(0.5f * (vb.xyz + vi.xyz) + 0.5f * dt * a.xyz, vb.w);
  }
}

// Main's form: one work-item per element, the neighbour through the padded grid.
kernel void stage_gather(global const float4* us, global const float4* vs, global const float4* ub,
                         global const float4* vb, global float4* uo, global float4* vo, global const int* grid,
                         global const uint* cell_of, int sy, int sz, float h, float dt, float zeta, int second,
                         uint n) {
  const uint e = get_global_id(0);
  if (e >= n) return;
  const int cell = (int)cell_of[e];
  const float4 ui = us[e], vE = vs[e];
  const float4 vi = (float4)(vE.xyz, 0);
  float4 f = (float4)(0);
#pragma unroll
  for (int d = 0; d < 26; ++d) {
    const int jn = grid[cell + DX[d] + sy * DY[d] + sz * DZ[d]];
    const int j = jn >= 0 ? jn : (int)e;
    const float4 vj = vs[j];
    f += connection(ui, vi, vE.w, us[j], vj, jn >= 0 ? vj.w : 0.0f, d, h, zeta);
  }
  float4 a, b;
  advance(ui, vE, f, second ? ub[e] : ui, second ? vb[e] : vE, dt, second, &a, &b);
  uo[e] = a;
  vo[e] = b;
}

// Buffers, a 3-D range: the work-group's shape decides which neighbours it shares.
kernel void stage_buf3d(global const float4* us, global const float4* vs, global const float4* ub,
                        global const float4* vb, global float4* uo, global float4* vo, float h, float dt,
                        float zeta, int second, int N) {
  const int x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
  if (x >= N || y >= N || z >= N) return;
  const int e = x + N * (y + N * z);
  const float4 ui = us[e], vE = vs[e];
  const float4 vi = (float4)(vE.xyz, 0);
  float4 f = (float4)(0);
#pragma unroll
  for (int d = 0; d < 26; ++d) {
    const int nx = x + DX[d], ny = y + DY[d], nz = z + DZ[d];
    const int in = (uint)nx < (uint)N && (uint)ny < (uint)N && (uint)nz < (uint)N;
    const int j = in ? e + DX[d] + N * (DY[d] + N * DZ[d]) : e;
    const float4 vj = vs[j];
    f += connection(ui, vi, vE.w, us[j], vj, in ? vj.w : 0.0f, d, h, zeta);
  }
  float4 a, b;
  advance(ui, vE, f, second ? ub[e] : ui, second ? vb[e] : vE, dt, second, &a, &b);
  uo[e] = a;
  vo[e] = b;
}

constant sampler_t S = CLK_NORMALIZED_COORDS_FALSE | CLK_ADDRESS_CLAMP | CLK_FILTER_NEAREST;

// 3-D images: outside the cube the border texel (0, 0, 0, 0) has E = 0.
kernel void stage_img3d(read_only image3d_t us, read_only image3d_t vs, read_only image3d_t ub,
                        read_only image3d_t vb, write_only image3d_t uo, write_only image3d_t vo, float h, float dt,
                        float zeta, int second, int N) {
#ifdef IMG3D_WRITES
  const int x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
  if (x >= N || y >= N || z >= N) return;
  const int4 c = (int4)(x, y, z, 0);
  const float4 ui = read_imagef(us, S, c), vE = read_imagef(vs, S, c);
  const float4 vi = (float4)(vE.xyz, 0);
  float4 f = (float4)(0);
#pragma unroll
  for (int d = 0; d < 26; ++d) {
    const int4 cj = c + (int4)(DX[d], DY[d], DZ[d], 0);
    const float4 vj = read_imagef(vs, S, cj);
    f += connection(ui, vi, vE.w, read_imagef(us, S, cj), vj, vj.w, d, h, zeta);
  }
  float4 a, b;
  advance(ui, vE, f, second ? read_imagef(ub, S, c) : ui, second ? read_imagef(vb, S, c) : vE, dt, second, &a, &b);
  write_imagef(uo, c, a);
  write_imagef(vo, c, b);
#endif
}

// 2-D images of N × N² texels (row y + N z); rows of another z slab are outside by test.
kernel void stage_img2d(read_only image2d_t us, read_only image2d_t vs, read_only image2d_t ub,
                        read_only image2d_t vb, write_only image2d_t uo, write_only image2d_t vo, float h, float dt,
                        float zeta, int second, int N) {
  const int x = get_global_id(0), y = get_global_id(1), z = get_global_id(2);
  if (x >= N || y >= N || z >= N) return;
  const int2 c = (int2)(x, y + N * z);
  const float4 ui = read_imagef(us, S, c), vE = read_imagef(vs, S, c);
  const float4 vi = (float4)(vE.xyz, 0);
  float4 f = (float4)(0);
#pragma unroll
  for (int d = 0; d < 26; ++d) {
    const int ny = y + DY[d], nz = z + DZ[d];
    const int in = (uint)ny < (uint)N && (uint)nz < (uint)N;
    const int2 cj = in ? (int2)(x + DX[d], ny + N * nz) : (int2)(-1, 0);
    const float4 vj = read_imagef(vs, S, cj);
    f += connection(ui, vi, vE.w, read_imagef(us, S, cj), vj, vj.w, d, h, zeta);
  }
  float4 a, b;
  advance(ui, vE, f, second ? read_imagef(ub, S, c) : ui, second ? read_imagef(vb, S, c) : vE, dt, second, &a, &b);
  write_imagef(uo, c, a);
  write_imagef(vo, c, b);
}

kernel void copy4(global const float4* a, global float4* b) { b[get_global_id(0)] = a[get_global_id(0)]; }
