#pragma once
/// Work-group sizes, launch limits and the kernels' argument layout, as the simulator's parts
/// (engine/sim/simulator*.cpp) set them: each must match its kernel (kernels/*.cl).
#include <cstddef>

namespace vb {

inline constexpr int kCheckWorkGroup = 128;
// volume_project's work-groups on GPUs (kernels/volume.cl): its last group applies the projection
// to the whole surface, so wide groups keep that tail short
inline constexpr std::size_t kVolumeGpuWorkGroup = 512;
// VB_SPLIT (kernels/integrate.cl): work-group size of the split Heun kernels, and the model size
// up to which GPUs split: Ogden on the H200 gained 3–9% at 36k and 76k, lost 4.5% at 125k (cube)
// and 13.5% at 262k (cube), 6–23% at 147k–246k (phantom; docs/PERFORMANCE.md, "Launches per step")
inline constexpr std::size_t kSplitWorkGroup = 128, kSplitMaxElements = 98304;
// Spring models up to this size take Heun's one-launch step on NVIDIA (kernels/persistent.cl):
// up to 43k cubes it held ~70k steps/s in every round while the launched step, host-bound there,
// ranged 60–78k (level in the mean); at 47k the launched step won by 3%, at 64k–216k by 26–53%
// (H200; docs/PERFORMANCE.md, "Launches per step").
inline constexpr std::size_t kPersistentMaxElements = 45056;
// VB_LANE_WIDTH (kernels/integrate_lanes.cl): free elements per work-item of the CPU lanes kernels
inline constexpr std::size_t kLaneWidth = 8;
inline constexpr int kCheckBaseSlots = 6, kCheckSlotsPerIndenter = 4;  // kernels/checks.cl
inline constexpr int kCheckSlotsPerTorus = 8;                             // VB_TORUS_SLOTS
inline constexpr int kIndenterStride = 20;                                // VB_IND_STRIDE
inline constexpr int kTorusStride = 12;                                   // VB_TORUS_STRIDE
// Kernel argument layout (kernels/common.cl): VB_LATTICE_KERNEL_PARAMS (the arena, its offsets,
// then the scalars; gravity 7th) then VB_INDENTER_PARAMS.
inline constexpr int kLatticeArgs = 10, kLatticeGravity = 6, kIndenterArgs = 3;
inline constexpr int kStepLattice = 4;  // step kernels: the 4 state arrays' offsets first (the state arena last)
inline constexpr int kStepIndenter = kStepLattice + kLatticeArgs;   // then dt, n
inline constexpr int kCheckLattice = 2;                             // check_state: u, v first
inline constexpr int kCheckIndenter = kCheckLattice + kLatticeArgs; // then partial, partial_arg, n, scale
// With VB_TRI_CONTACT the stepping and check kernels end with VB_TRI_PARAMS
// (kernels/triangle_contact.cl): corner forces, CSR start, corners, triangle count.
inline constexpr int kTriangleArgs = 4;
inline constexpr int kCheckVolume = kCheckIndenter + kIndenterArgs + 4;  // VB_VOLUME: grad, scalars
// kernels/volume.cl: volume_partials takes u, v, the lattice parameters, then these.
inline constexpr int kVolumeSlots = 5, kVolumeScalars = 5;  // scalars: λ, μ, V, p, M (kernels/volume.cl)
inline constexpr int kVolumeMesh = 2 + kLatticeArgs;  // mesh arena, its offsets, n_surf
inline constexpr int kVolumeCentre = kVolumeMesh + 3, kVolumeWithForce = kVolumeMesh + 5;
// volume_project: u, v, the lattice parameters, the mesh, centre, then grad, partial, V0, scalars, count
inline constexpr int kProjectGrad = kVolumeCentre + 1, kProjectRestVolume = kVolumeCentre + 3;
// volume_apply: u, v, mesh arena, its offsets, n_surface, grad, partial, groups, V0, scalars (the
// state arrays as state arena offsets, the arena last; volume_partials likewise)
inline constexpr int kApplyRestVolume = 8;

}  // namespace vb
