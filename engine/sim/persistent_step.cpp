#include "engine/sim/persistent_step.hpp"

#include <algorithm>
#include <cstdlib>
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

PersistentPlan plan_persistent_step(const DeviceInfo& device, bool eligible, bool hyperelastic, std::size_t elements,
                                    int force_split, std::size_t max_elements) {
  PersistentPlan plan;
  const bool possible = eligible && nvidia_ptx(device) && device.compute_units > 0;
  plan.on = possible && !hyperelastic && elements <= max_elements;
  if (const char* env = std::getenv("VOXBREAST_PERSISTENT")) plan.on = possible && std::atoi(env) == 1;
  if (!plan.on) return plan;
  constexpr std::size_t kMinPerUnit = 2, kMaxPerUnit = 6;
  const std::size_t per_block = PersistentPlan::kWorkGroup / std::size_t(std::max(force_split, 1));
  const std::size_t blocks = (elements + per_block - 1) / per_block;
  std::size_t per_unit =
      std::clamp((blocks + device.compute_units - 1) / device.compute_units, kMinPerUnit, kMaxPerUnit);
  if (const char* env = std::getenv("VOXBREAST_PERSISTENT_GROUPS"))  // per compute unit, to compare
    per_unit = std::clamp<std::size_t>(std::size_t(std::max(std::atoi(env), 1)), 1, 8);
  const char* trace = std::getenv("VOXBREAST_PERSISTENT_TRACE");
  plan.trace = trace && std::atoi(trace) == 1;
  plan.groups = per_unit * device.compute_units;
  if (const char* env = std::getenv("VOXBREAST_PERSISTENT_GROUP_LIMIT"))  // tests: several blocks per group
    plan.groups = std::clamp<std::size_t>(std::size_t(std::max(std::atoi(env), 1)), 1, plan.groups);
  plan.max_registers = int(std::min<std::size_t>(255, kRegistersPerUnit / (PersistentPlan::kWorkGroup * per_unit) / 8 * 8));
  return plan;
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
