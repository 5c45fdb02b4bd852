// Precision and feature switches shared by every kernel. The host passes
//   -DVB_DOUBLE=0|1   real = float | double
//   -DVB_GRAVITY=0|1, -DVB_DASHPOT=0|1, -DVB_GLOBAL_DAMPING=0|1, -DVB_INDENTERS=count
//                     so only what the scene uses is compiled
//   -DVB_RSQRT=0|1    1/|r| by rsqrt (GPUs) or 1/sqrt (CPUs, where rsqrt is a library call)
//   -DVB_HYPER=0|1    hyperelastic tissues present (kernels/hyperelastic.cl)
//   -DVB_BIPHASIC=0|1 biphasic-spring tissues present (kernels/lattice_forces.cl)
//   -DVB_CHECK_WG=N   work-group size of the reduction kernel
//   -DVB_VOLUME=0|1   volume-preservation constraint on (kernels/volume.cl)
//   -DVB_RELAX=0|1    dynamic relaxation (kernels/relax.cl): four more check slots
//   -DVB_TORI=count, -DVB_TORUS_BASE=N, -DVB_FRICTION=0|1  the torus device (kernels/device_contact.cl)
//   -DVB_TRI_CONTACT=0|1 some indenter touches the surface triangles (kernels/triangle_contact.cl)
//   -DVB_REST_OFFSET=0|1  the rest state is not the lattice: element e rests at its voxel centre
//                     plus rest_offset[e] (the unloaded reference state, docs/PHYSICS.md §13)
//   -DVB_VOLUME_FOLD=0|1  Heun with the volume constraint, projections applied by the kernels that
//                     read the state next (VB_PENDING_PARAMS below) instead of by volume_apply
//   -DVB_VOLUME_PAIRS=0|1  the volume gradient's incident triangles as element pairs (kernels/volume.cl)
//   -DVB_ARENA_UNIT=N  the unit of the arena offsets (bytes, engine/sim/device_arena.hpp)
//   -DVB_NV_PTX=0|1   NVIDIA device: inline PTX for device-scope fences (vb_device_fence)
//   -DVB_PERSISTENT=0|1  Heun's whole step in one launch (kernels/persistent.cl, NVIDIA only)
//   -DVB_PRED_PACKED=0|1  Heun's predicted stage packed (kernels/lattice_forces.cl, stage_load)
// and prepends the lattice tables (VB_DIR, VB_DIR_LEN, VB_KAPPA) generated from the host's
// single definition (engine/sim/kernel_tables.cpp).
#if VB_DOUBLE
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double real;
typedef double2 real2;
typedef double4 real4;
#else
typedef float real;
typedef float2 real2;
typedef float4 real4;
#endif

// The stepping path's functions are always inlined (docs/PERFORMANCE.md, "CPU lanes kernels"): PoCL's inliner
// left the unrolled force loop and its callers as calls, made for every work-item with ~25
// arguments on the stack; inlined, the same scalar code runs 1.4x faster. GPU compilers inline
// them anyway.
#define VB_INLINE inline __attribute__((always_inline))

// A fence at device scope: the writes before it are visible to every work-group that sees a later
// atomic. OpenCL 1.2's mem_fence(CLK_GLOBAL_MEM_FENCE) is only a work-group fence on NVIDIA (PTX
// membar.cta, seen in the PTX), so there the host passes -DVB_NV_PTX=1 and the fence is PTX's
// membar.gl (CUDA's __threadfence), which also makes this SM's later loads miss stale L1 lines.
inline void vb_device_fence(void) {
#if VB_NV_PTX
  asm volatile("membar.gl;" ::: "memory");
#else
  mem_fence(CLK_GLOBAL_MEM_FENCE);
#endif
}

inline real4 xyz0(real4 a) { return (real4)(a.x, a.y, a.z, 0); }
inline real dot3(real4 a, real4 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
// |a| for lengths far from overflow (lattice connections): OpenCL's length() guards against
// overflow, which NVIDIA compiles to three divisions and an IEEE square root per call.
inline real norm3(real4 a) { return sqrt(dot3(a, a)); }

// Heun's reversed corrector order (VB_CORRECT_REVERSE, kernels/integrate.cl; also the gather
// floor's, kernels/gather_floor.cl): work-item i takes the elements' aligned blocks of `block` from
// the last to the first, each block in order; UINT_MAX past the last block.
inline uint reverse_block_element(uint i, uint n, uint block) {
  const uint blocks = (n + block - 1) / block, b = i / block;
  return b < blocks ? (blocks - 1 - b) * block + i % block : UINT_MAX;
}

// Rest (voxel-centre) position of the element stored at padded grid cell `cell`.
// The padded grid has one empty voxel on every side: cell = (i+1) + sy·(j+1) + sz·(k+1).
inline real4 rest_position(uint cell, int sy, int sz, real4 origin, real h) {
  const int k = (int)(cell / (uint)sz);
  const int rem = (int)(cell - (uint)(k * sz));
  const int j = rem / sy;
  const int i = rem - j * sy;
  return (real4)(origin.x + h * (i - 1), origin.y + h * (j - 1), origin.z + h * (k - 1), 0);
}

// An element within this fraction of a spacing of the indenter surface is in contact.
#define REAL_CONTACT_TOL ((real)1e-3)

#if VB_DOUBLE
#define VB_EPSILON DBL_EPSILON
#else
#define VB_EPSILON FLT_EPSILON
#endif

// The smallest distance from a contact surface (m) that this precision tells from zero at x (lattice
// frame): x = X + u is rounded to half a spacing of its largest coordinate, so a distance computed
// from it steps by about that as u changes. A push contact takes a distance within this of zero as
// zero: chasing it made float elements on a surface move by a spacing per step for ever, a speed
// floor above 10⁻⁶ of the wave speed (docs/PHYSICS.md, "Float equilibrium floor").
inline real contact_resolution(real4 x) {
  return (real)4 * VB_EPSILON * fmax(fmax(fabs(x.x), fabs(x.y)), fabs(x.z));
}

// Parameters of the force and stepping helpers, in this order; kernels take
// VB_LATTICE_KERNEL_PARAMS (below, set by the host in one place) and name these with
// VB_UNPACK_LATTICE.
// Hyperelastic data (tissue_of, materials, Qs, Cs, hourglass) are 1-element placeholders when
// VB_HYPER is 0; tissue_of and materials are real when VB_BIPHASIC is 1; rest_offset (m, lattice
// frame) is a placeholder when VB_REST_OFFSET is 0.
#define VB_LATTICE_PARAMS                                                                        \
  global const real *E, global const uint *cell_of, global const int *grid, int sy, int sz,    \
      real h, real dashpot_ratio, real4 gravity, real damping, real4 origin,                   \
      global const uchar *tissue_of, global const real *materials, global const real4 *Qs,     \
      global const real4 *Cs, real hourglass, global const real4 *rest_offset
#define VB_LATTICE_ARGS \
  E, cell_of, grid, sy, sz, h, dashpot_ratio, gravity, damping, origin, tissue_of, materials, Qs, Cs, hourglass, \
      rest_offset
// What kernels take instead: the model's arrays in one buffer, the arena (engine/sim/device_arena.hpp:
// NVIDIA's OpenCL spends ~0.4 µs of host time per buffer argument of every launch), with each
// array's offset in units of VB_ARENA_UNIT bytes in `at`: E, cell_of, grid, tissue_of, materials,
// Q rows, C, rest offsets. VB_UNPACK_LATTICE at the top of a kernel names them as above.
#define VB_ARENA_AT(arena, slot) ((arena) + (size_t)(slot) * VB_ARENA_UNIT)
// The element stepping work-item i moves, and the bound to test it against (`n`, `arena` in
// scope). VB_STEP_LIST (GPUs; engine/sim/simulator.cpp): the free elements' list in the model
// arena at VB_STEP_LIST_AT, n its length; held elements get no work-item, and past the end the
// element is UINT_MAX, which fails every bound. Otherwise element i of n.
#if VB_STEP_LIST
#define VB_STEP_INDEX(i) ((i) < n ? ((global const uint*)VB_ARENA_AT(arena, VB_STEP_LIST_AT))[i] : UINT_MAX)
#define VB_STEP_N UINT_MAX
#else
#define VB_STEP_INDEX(i) (i)
#define VB_STEP_N n
#endif
#define VB_LATTICE_KERNEL_PARAMS                                                                 \
  global const uchar *arena, uint8 at, int sy, int sz, real h, real dashpot_ratio, real4 gravity, \
      real damping, real4 origin, real hourglass
// The same parameters passed on by a kernel to a helper that takes VB_LATTICE_KERNEL_PARAMS.
#define VB_LATTICE_KERNEL_ARGS arena, at, sy, sz, h, dashpot_ratio, gravity, damping, origin, hourglass
#define VB_UNPACK_LATTICE                                                                \
  global const real* E = (global const real*)VB_ARENA_AT(arena, at.s0);                \
  global const uint* cell_of = (global const uint*)VB_ARENA_AT(arena, at.s1);           \
  global const int* grid = (global const int*)VB_ARENA_AT(arena, at.s2);                \
  global const uchar* tissue_of = VB_ARENA_AT(arena, at.s3);                            \
  global const real* materials = (global const real*)VB_ARENA_AT(arena, at.s4);         \
  global const real4* Qs = (global const real4*)VB_ARENA_AT(arena, at.s5);              \
  global const real4* Cs = (global const real4*)VB_ARENA_AT(arena, at.s6);              \
  global const real4* rest_offset = (global const real4*)VB_ARENA_AT(arena, at.s7)
// A pending volume projection (kernels/volume.cl, VB_VOLUME_FOLD): the state in memory is the
// unprojected (u, v), and its readers see what volume_apply would have stored,
//   u + λ·(w·g),  v − μ·(w·g)   (g = pend_g[j], zero off the surface; w = u.w),
// with the same operations as volume_apply_one, so the values are those of the two-launch form.
// `pending` is a constant at every call (0: no projection; the compiler drops the loads).
#define VB_PENDING_PARAMS global const real4 *pend_g, real pend_lambda, real pend_mu, int pending
#define VB_PENDING_ARGS pend_g, pend_lambda, pend_mu, pending
#define VB_NO_PENDING (global const real4*)0, (real)0, (real)0, 0
// Element j's displacement uj as the projection leaves it; wg gets w·g (kept for its velocity).
inline void pending_u(real4* uj, real4* wg, uint j, VB_PENDING_PARAMS) {
  if (!pending) return;
  *wg = uj->w * pend_g[j];
  *uj = *uj + pend_lambda * *wg;
}
inline void pending_v(real4* vj, real4 wg, VB_PENDING_PARAMS) {
  if (pending) *vj = *vj - pend_mu * wg;
}

// Rigid indenters: a table of VB_INDENTERS rows (lattice frame, VB_IND_STRIDE reals each:
// 0–2 start (m), 3 radius (m; -1 for a plate), 4–6 plate normal into the tissue / cylinder and
// capsule axis (unit), 8–10 velocity (m/s), 12 travel time (s), 13 contact: 0 push, 1 slide,
// 2 stick, 14 kind: 0 sphere, 1 plate, 2 cylinder, 3 capsule, 15 capsule segment length (m),
// 16 time t0 (s) at which the indenter is at `start`, 17 Coulomb friction μ (push contact),
// 18 contact surface: 0 vertices, 1 triangles (kernels/triangle_contact.cl), 19 its penalty
// stiffness (N/m); 7 and 11 unused: new columns go at the end), the time forces are evaluated at, and
// the time stage positions are projected at.
// A 1-row placeholder when VB_INDENTERS is 0. Torus rows and their
// inflation knots follow from VB_TORUS_BASE (kernels/device_contact.cl): the rigid-obstacle table.
#define VB_IND_STRIDE 20
#define VB_INDENTER_PARAMS global const real *indenters, real t_force, real t_project
#define VB_INDENTER_ARGS indenters, t_force, t_project

// The state arena (Simulator::state_, engine/sim/device_arena.hpp): u, v, ũ, ṽ, the rest frame,
// the obstacle table and the volume constraint's gradient, partial sums and scalars in one buffer.
// The kernels a step launches (the stepping kernels, element_stress, volume_partials,
// volume_apply) take it as their last argument and each of those arrays as its offset (units of
// VB_ARENA_UNIT bytes) where a buffer argument would be: one buffer argument instead of up to
// six per launch (docs/PERFORMANCE.md, "State layout and the arena"). Other kernels take the arrays as buffers (the
// host's sub-buffers); no kernel takes both the arena and a sub-buffer of it (OpenCL leaves
// concurrent use of a buffer and its sub-buffers undefined).
#define VB_STATE_PARAM , global uchar *state_arena
#define VB_STATE_AT(type, slot) ((global type*)VB_ARENA_AT(state_arena, slot))
#define VB_INDENTER_AT_PARAMS uint indenters_at, real t_force, real t_project
#define VB_UNPACK_INDENTERS global const real* indenters = VB_STATE_AT(const real, indenters_at)
