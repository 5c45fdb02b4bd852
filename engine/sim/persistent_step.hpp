#pragma once
/// Heun's whole step in one launch on NVIDIA GPUs (kernels/persistent.cl): when to use it, and how
/// many work-groups to launch so that all are resident at once (they wait for each other).
#include <cstddef>
#include <string>

namespace vb {

struct DeviceInfo;

/// The device takes inline PTX (NVIDIA's OpenCL): device-scope fences, the persistent step.
bool nvidia_ptx(const DeviceInfo& device);

struct PersistentPlan {
  bool on = false;
  std::size_t groups = 0;   ///< work-groups of kWorkGroup work-items, all resident (fit_registers)
  int max_registers = 0;    ///< per work-item, so that groups / compute units fit on one
  bool trace = false;       ///< pass times printed at each check (PlanOverrides::persistent_trace)
  static constexpr std::size_t kWorkGroup = 128;  ///< VB_PERSISTENT_WG
  /// build options: -DVB_PERSISTENT=0|1 and, when on, NVIDIA's register cap and -cl-nv-verbose (the
  /// build log then says how many registers the kernel uses: registers_in_build_log)
  std::string options() const;
  /// Lowers `groups` to what `compute_units` hold when the built kernel uses `registers` per
  /// work-item (registers_in_build_log; ≤ 0: unknown, the plan stays): NVIDIA's compiler may exceed
  /// the cap (96 against 80 for the double step), and a group that never starts stalls the barriers.
  void fit_registers(int registers, std::size_t compute_units);
};

/// The register cap per work-item when `groups_per_unit` groups of kWorkGroup work-items share one
/// NVIDIA compute unit: 65,536 / (128 · groups per unit), in multiples of 8, at most 255. (When the
/// plan takes the one-launch step and how many groups it launches: launch_plan.cpp.)
int persistent_register_cap(std::size_t groups_per_unit);

/// The registers per work-item that NVIDIA's compiler reports for `kernel` in a build log made
/// with -cl-nv-verbose ("Compiling entry function 'kernel'", then "Used N registers"); -1 where
/// the log does not say.
int registers_in_build_log(const std::string& log, const std::string& kernel);

/// Work-groups of `work_group` work-items using `registers` registers each that one NVIDIA compute
/// unit holds at once (65,536 registers, allocated per warp in multiples of 8 per work-item).
std::size_t groups_per_unit_by_registers(int registers, std::size_t work_group);

}  // namespace vb
