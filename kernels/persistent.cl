// Heun's whole step in one launch (-DVB_PERSISTENT=1; NVIDIA GPUs, small models; docs/PERFORMANCE.md,
// "One-launch persistent step"). A step is up to 8 dependent passes, and NVIDIA's OpenCL spends ~5 µs of host time
// per launch, more than the passes themselves take at 36k elements. Here one launch of
// co-resident work-groups runs the passes in turn, each over the whole model (a group takes
// blocks of elements, strided by the number of groups), with a grid-wide barrier between them:
//   [element_stress(u)]  predict(u, v → ũ, ṽ)  [volume partials(ũ, ṽ)  volume apply(ũ, ṽ)]
//   [element_stress(ũ)]  correct(ũ, ṽ → u, v)  [volume partials(u, v)  volume apply(u, v)]
// (brackets: hyperelastic tissue present; the volume projection of this step). The passes compute
// what the separate kernels compute, in the same order per element and per partial sum.
//
// Work-groups wait for each other, so all must be resident at once: the host launches at most as
// many as the device holds (groups per compute unit × compute units, with a register cap that
// makes them fit; engine/sim/simulator_persistent.cpp). OpenCL promises no such thing in general,
// so this is an NVIDIA-only path (PoCL would deadlock); a barrier that waits too long sets a fault
// flag that the host reports instead of hanging.
#if VB_PERSISTENT
#define VB_PERSISTENT_WG 128
#if VB_CHECK_WG != VB_PERSISTENT_WG || (VB_SPLIT > 1 && VB_SPLIT_WG != VB_PERSISTENT_WG)
#error "the persistent step's work-groups must match the volume sums' and the split force passes'"
#endif
#define VB_GRID_SPIN_LIMIT (1u << 24)

// -DVB_PERSISTENT_TRACE=1 (--plan persistent_trace=1): work-group 0 stamps the GPU's ns clock at
// the start and after every grid barrier into sync[2 + k], which the host prints at each check.
#if VB_PERSISTENT_TRACE
inline void trace_stamp(volatile global uint* sync, uint k) {
  if (get_global_id(0) == 0) {
    ulong t;
    asm volatile("mov.u64 %0, %%globaltimer;" : "=l"(t));
    sync[2 + k] = (uint)t;
  }
}
#else
#define trace_stamp(sync, k)
#endif

// Grid-wide barrier: every group counts itself in sync[0] and waits until the count reaches
// `target` (it grows by the number of groups per barrier; the host passes each launch's start, and
// the comparison survives the count's wrap-around). In each group item 0 fences, between
// work-group barriers: its device fence (membar.gl) publishes the group's writes before it counts
// and, after the wait, makes the SM's loads miss lines other groups have since written (with
// OpenCL's mem_fence instead, a test kernel read stale L1 lines: docs/PERFORMANCE.md).
inline void grid_barrier(volatile global uint* sync, uint target, uint* stamps) {
  barrier(CLK_GLOBAL_MEM_FENCE | CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0) {
    vb_device_fence();
    atomic_inc(sync);
    uint spins = 0;
    while ((int)(atomic_add(sync, 0u) - target) < 0)
      if (++spins == VB_GRID_SPIN_LIMIT) {  // a group never came: report, do not hang
        atomic_xchg(sync + 1, 1u);
        break;
      }
    vb_device_fence();
  }
  barrier(CLK_GLOBAL_MEM_FENCE | CLK_LOCAL_MEM_FENCE);
  trace_stamp(sync, ++*stamps);
}

#if VB_SPLIT > 1
#define VB_BLOCK_ELEMENTS VB_SPLIT_PER
#define VB_BLOCK_ELEMENT(block) split_element(block)
#else
#define VB_BLOCK_ELEMENTS VB_PERSISTENT_WG
#define VB_BLOCK_ELEMENT(block) ((block) * VB_PERSISTENT_WG + get_local_id(0))
#endif
// every group walks the blocks of `count` items it owns (uniform in the group: barriers inside are safe)
#define VB_FOR_BLOCKS(b, count) for (uint b = get_group_id(0); b < (count); b += get_num_groups(0))
// The split force passes' `share`: part 0 reads the other parts' sums after a barrier, so the
// next block's parts may write it only after another.
#if VB_SPLIT > 1
#define VB_BLOCK_DONE barrier(CLK_LOCAL_MEM_FENCE)
#else
#define VB_BLOCK_DONE
#endif

#if VB_HYPER
inline void stress_pass(global const real4* u, global uchar* arena, uint8 at, int sy, int sz, real h, uint n,
                        global const real4* rest_frame) {
  for (uint e = get_global_id(0); e < n; e += get_global_size(0))
    element_stress_one(e, u, arena, at, sy, sz, h, rest_frame, VB_NO_PENDING, VB_NOT_PREDICTED);
}
#endif

#if VB_VOLUME
// The projection of (u, v): the partial sums, a grid barrier, then every group sums the partials
// itself (as volume_apply does) and applies x += λ·w·g, v −= μ·w·g to its share of the surface.
inline void volume_pass(global real4* u, global real4* v, VB_LATTICE_PARAMS, VB_VOLUME_MESH_PARAMS,
                        global real4* grad, global real* partial, uint vol_groups, real rest_volume,
                        global real* scalars, local real* s, volatile global uint* sync, uint target,
                        uint* stamps) {
  VB_FOR_BLOCKS(g, vol_groups)
  volume_group_partials(g, u, v, VB_LATTICE_ARGS, VB_VOLUME_MESH_ARGS, grad, 0, partial, s);
  grid_barrier(sync, target, stamps);
  // only the groups with surface elements to move sum the partials (uniform in a group)
  if (get_group_id(0) * VB_PERSISTENT_WG >= n_surface) return;
  real out[4];
  volume_scalars(partial, vol_groups, rest_volume, s, VB_PERSISTENT_WG, get_local_id(0), out);
  if (get_global_id(0) == 0)
    for (int k = 0; k < 4; ++k) scalars[k] = out[k];
  for (uint i = get_global_id(0); i < n_surface; i += get_global_size(0)) {
    const uint e = surface_elements[i];
    volume_apply_one(e, u, v, grad[e], out);
  }
}
#endif

// Arguments: the state and the predicted stage, the lattice (VB_LATTICE_KERNEL_PARAMS with the
// arena writable: the stress passes store Q and C there), the obstacles and the stage times t0, t1,
// dt, n, the rest frames; with VB_VOLUME the mesh, gradient, partials, their group count, V0,
// scalars and whether this step projects; then the barrier count and fault flag and this
// launch's first barrier target.
kernel __attribute__((reqd_work_group_size(VB_PERSISTENT_WG, 1, 1)))
void heun_step_persistent(global real4* u, global real4* v, global real4* u_pred, global real4* v_pred,
                          global uchar* arena_rw, uint8 at, int sy, int sz, real h, real dashpot_ratio,
                          real4 gravity, real damping, real4 origin, real hourglass, global const real* indenters,
                          real t0, real t1, real dt, uint n, global const real4* rest_frame,
#if VB_VOLUME
                          global const uchar* mesh, uint4 mesh_at, uint n_surface, real4 centre,
                          global real4* grad, global real* partial, uint vol_groups, real rest_volume,
                          global real* scalars, int project,
#endif
                          volatile global uint* sync, uint target) {
  global const uchar* arena = arena_rw;
  VB_UNPACK_LATTICE;
#if VB_VOLUME
  VB_UNPACK_MESH;
  local real s[VB_VOLUME_SLOTS * VB_PERSISTENT_WG];
#endif
#if VB_SPLIT > 1
  local real4 share[VB_SPLIT_WG];
#else
  local real4* share = 0;
#endif
  const uint groups = get_num_groups(0), blocks = (n + VB_BLOCK_ELEMENTS - 1) / VB_BLOCK_ELEMENTS;
  uint stamps = 0;
  trace_stamp(sync, 0);
#define VB_NEXT_BARRIER (target += groups)
#if VB_HYPER
  stress_pass(u, arena_rw, at, sy, sz, h, n, rest_frame);
  grid_barrier(sync, VB_NEXT_BARRIER, &stamps);
#endif
  VB_FOR_BLOCKS(b, blocks) {
    predict_element(VB_BLOCK_ELEMENT(b), u, v, u_pred, v_pred, VB_LATTICE_ARGS, indenters, t0, t1, dt, n,
                    VB_NO_PENDING, VB_NO_LAG, share);
    VB_BLOCK_DONE;
  }
  grid_barrier(sync, VB_NEXT_BARRIER, &stamps);
#if VB_VOLUME
  if (project) {
    volume_pass(u_pred, v_pred, VB_LATTICE_ARGS, VB_VOLUME_MESH_ARGS, grad, partial, vol_groups, rest_volume,
                scalars, s, sync, VB_NEXT_BARRIER, &stamps);
    grid_barrier(sync, VB_NEXT_BARRIER, &stamps);
  }
#endif
#if VB_HYPER
  stress_pass(u_pred, arena_rw, at, sy, sz, h, n, rest_frame);
  grid_barrier(sync, VB_NEXT_BARRIER, &stamps);
#endif
  VB_FOR_BLOCKS(b, blocks) {
    correct_element(VB_BLOCK_ELEMENT(b), u, v, u_pred, v_pred, VB_LATTICE_ARGS, indenters, t1, t1, dt, n,
                    VB_NO_PENDING, VB_NO_PENDING, share);
    VB_BLOCK_DONE;
  }
#if VB_VOLUME
  if (project) {
    grid_barrier(sync, VB_NEXT_BARRIER, &stamps);
    volume_pass(u, v, VB_LATTICE_ARGS, VB_VOLUME_MESH_ARGS, grad, partial, vol_groups, rest_volume, scalars, s, sync,
                VB_NEXT_BARRIER, &stamps);
  }
#endif
#undef VB_NEXT_BARRIER
  barrier(CLK_GLOBAL_MEM_FENCE);
  trace_stamp(sync, stamps + 1);  // group 0's end (the others may still run)
}
#endif  // VB_PERSISTENT
