#include "engine/sim/persistent_step.hpp"

#include <algorithm>
#include <exception>
#include <string>

#include "engine/sim/opencl_runtime.hpp"

namespace vb {
namespace {
constexpr std::size_t kRegistersPerUnit = 65536;  // an NVIDIA compute unit's register file
}  // namespace

bool nvidia_ptx(const DeviceInfo& device) {
  return device.is_gpu && (device.platform.find("NVIDIA") != std::string::npos ||
                           device.vendor.find("NVIDIA") != std::string::npos);
}

std::string PersistentPlan::options() const {
  if (!on) return " -DVB_PERSISTENT=0";
  return " -DVB_PERSISTENT=1 -DVB_PERSISTENT_TRACE=" + std::to_string(trace) +
         " -cl-nv-maxrregcount=" + std::to_string(max_registers) + " -cl-nv-verbose";
}

void PersistentPlan::fit_registers(int registers, std::size_t compute_units) {
  if (!on || registers <= 0) return;
  groups = std::min(groups, std::max<std::size_t>(1, groups_per_unit_by_registers(registers, kWorkGroup) * compute_units));
}

int persistent_register_cap(std::size_t groups_per_unit) {
  const std::size_t per_unit = std::max<std::size_t>(groups_per_unit, 1);
  return int(std::min<std::size_t>(255, kRegistersPerUnit / (PersistentPlan::kWorkGroup * per_unit) / 8 * 8));
}

int registers_in_build_log(const std::string& log, const std::string& kernel) {
  const std::size_t entry = log.find("Compiling entry function '" + kernel + "'");
  if (entry == std::string::npos) return -1;
  const std::size_t next = log.find("Compiling entry function", entry + 1);
  const std::size_t used = log.find("Used ", entry);
  if (used == std::string::npos || used > next) return -1;
  const std::size_t end = log.find(" registers", used);
  if (end == std::string::npos || end > next) return -1;
  try {
    return std::stoi(log.substr(used + 5, end - used - 5));
  } catch (const std::exception&) {
    return -1;
  }
}

std::size_t groups_per_unit_by_registers(int registers, std::size_t work_group) {
  const std::size_t per_item = (std::size_t(std::max(registers, 1)) + 7) / 8 * 8;
  return kRegistersPerUnit / (per_item * work_group);
}

}  // namespace vb
