// The gather floor: the benchmark times Heun's two stepping kernels on the GPUs' plain path
// (kernels/integrate.cl with VB_UNIFORM_PATH and VB_PRED_PACKED) with their connection arithmetic
// taken out, in the same run as the step, to state how close the step comes to the cost of its own
// memory reads. Each work-item reads what the stage it stands for reads (the element's own state,
// E, cell, its 26 grid entries and the 26 neighbours' state, in the same layout and order) and
// writes what that stage writes; the neighbours' words are only combined by XOR (2-3 instructions
// a neighbour), so that the compiler keeps every load. The results are meaningless as physics;
// the stage is written into the floor's own buffers. Built with -DVB_DOUBLE=0 (float words) and
// -DVB_FLOOR_DASHPOT=0|1 as the step's VB_DASHPOT: only the connection dashpots read the
// neighbours' velocities. docs/PERFORMANCE.md, "What bounds the step: the gather floor".
#ifndef VB_FLOOR_DASHPOT
#define VB_FLOOR_DASHPOT 1
#endif

#define VB_BITS(x) as_uint(x)

// Neighbour d of the element at `cell` as the step finds it: its grid entry, or the element itself
// where the cell is empty (the step reads it and masks the connection out).
inline uint floor_neighbour(global const int* grid, int cell, int sy, int sz, uint e, int d) {
  const int jn = grid[cell + VB_DIR[d][0] + sy * VB_DIR[d][1] + sz * VB_DIR[d][2]];
  return jn >= 0 ? (uint)jn : e;
}

// The predictor's reads: u, v as real4 (x, y, z of each; v only with dashpots), own u, v, E, cell;
// writes the packed stage (u: ũx, ũy, ũz, ṽx; v2: ṽy, ṽz). Held elements (u.w = 0) only copy, as
// in the step.
kernel void gather_floor_predict(global const real4* u, global const real4* v, global const int* grid,
                                 global const uint* cell_of, global const real* E, int sy, int sz,
                                 global real4* u_pred, global real2* v_pred, uint n) {
  const uint e = get_global_id(0);
  if (e >= n) return;
  real4 ui = u[e], vi = v[e];
  if (ui.w != 0) {
    const int cell = (int)cell_of[e];
    uint acc = VB_BITS(E[e]);
#pragma unroll
    for (int d = 0; d < 26; ++d) {
      const uint j = floor_neighbour(grid, cell, sy, sz, e, d);
      const real4 uj = u[j];
      acc ^= VB_BITS(uj.x) ^ VB_BITS(uj.y) ^ VB_BITS(uj.z);
#if VB_FLOOR_DASHPOT
      const real4 vj = v[j];
      acc ^= VB_BITS(vj.x) ^ VB_BITS(vj.y) ^ VB_BITS(vj.z);
#endif
    }
    vi.x = as_float(VB_BITS(vi.x) ^ acc);
  }
  u_pred[e] = (real4)(ui.x, ui.y, ui.z, vi.x);
  v_pred[e] = (real2)(vi.y, vi.z);
}

// The corrector's reads: the packed stage of the element and its neighbours (real4 + real2; the
// neighbours' ũ alone without dashpots), the element's inverse mass from u.w, E, cell, then its own
// u, v; writes u, v. Over the elements' blocks of `block` last to first when `reverse`
// (VB_CORRECT_REVERSE), in order otherwise.
kernel void gather_floor_correct(global real4* u, global real4* v, global const int* grid, global const uint* cell_of,
                                 global const real* E, int sy, int sz, global const real4* u_pred,
                                 global const real2* v_pred, uint n, int reverse, uint block) {
  const uint e = reverse ? reverse_block_element(get_global_id(0), n, block) : get_global_id(0);
  if (e >= n) return;
  const real4 up = u_pred[e];
  const real2 vp = v_pred[e];
  if (u[e].w == 0) return;
  const int cell = (int)cell_of[e];
  uint acc = VB_BITS(E[e]) ^ VB_BITS(up.x) ^ VB_BITS(up.y) ^ VB_BITS(up.z) ^ VB_BITS(up.w) ^ VB_BITS(vp.x) ^
             VB_BITS(vp.y);
#pragma unroll
  for (int d = 0; d < 26; ++d) {
    const uint j = floor_neighbour(grid, cell, sy, sz, e, d);
    const real4 uj = u_pred[j];  // ũx, ũy, ũz, ṽx
    acc ^= VB_BITS(uj.x) ^ VB_BITS(uj.y) ^ VB_BITS(uj.z);
#if VB_FLOOR_DASHPOT
    const real2 vj = v_pred[j];  // ṽy, ṽz
    acc ^= VB_BITS(uj.w) ^ VB_BITS(vj.x) ^ VB_BITS(vj.y);
#endif
  }
  real4 ui = u[e], vi = v[e];
  ui.x = as_float(VB_BITS(ui.x) ^ acc);
  vi.x = as_float(VB_BITS(vi.x) ^ (acc >> 1));
  u[e] = ui;
  v[e] = vi;
}
