#pragma once
/// Work-items per group of the stepping kernels on GPUs where each work-item steps one element or
/// one listed element (kernels/integrate.cl, relax.cl; not the split force pass, the one-launch step
/// or the CPU lanes kernels, which have their own): 256 from 131,072 elements, 128 below. Measured
/// on the H200 (docs/PERFORMANCE.md, "Work-group sizes"): groups of 256 took 10–12% off the Heun step of the
/// 1.5M and 4.1M linear cubes, 4–5% off 512k and 2–4% off 262k (springs, neo-Hookean and Ogden,
/// with and without the volume constraint), 8% off the 1.5M phantom (step list) and 3–5% off the
/// 500k phantom (Heun, symplectic Euler, relaxation); below, level within the noise (the 64k cube
/// +1%, the 120k phantom −2% to +1%). 512 lost at 512k and 1,024 everywhere. Why: the neighbour
/// rows a group's warps share in their SM's L1. Nsight Compute on the prototype's step at 1.5M
/// measured the L1 hit rate at 76% in groups of 256 against 66% in
/// groups of 128, and 12% less L2 traffic. (Groups shaped as tiles shrank the
/// footprint further but gained at most 2.6%: the cube's partial tiles idle lanes.)
#include <cstddef>

namespace vb {

constexpr std::size_t kStepWorkGroup = 128, kStepWorkGroupLarge = 256, kStepWorkGroupLargeFrom = 131072;

constexpr std::size_t default_step_work_group(std::size_t elements) {
  return elements >= kStepWorkGroupLargeFrom ? kStepWorkGroupLarge : kStepWorkGroup;
}

/// A group size asked for (PlanOverrides::step_work_group, to compare sizes on a device), checked: a
/// multiple of 32 (the marks of the short connection loop are whole warps) within what the device
/// allows. Throws vb::Error naming the problem otherwise.
std::size_t checked_step_work_group(std::size_t size, std::size_t device_max);

}  // namespace vb
