#include "engine/study/sweep_devices.hpp"

#include <cstdlib>

#include "engine/error.hpp"

namespace vb {

std::vector<DeviceInfo> sweep_devices(const std::string& spec) {
  if (spec.empty()) return {select_device("")};
  if (spec == "all") {
    const std::vector<DeviceInfo> devices = list_devices();
    const bool gpu = select_device("").is_gpu;
    std::vector<DeviceInfo> same_kind;
    for (const DeviceInfo& d : devices)
      if (d.is_gpu == gpu) same_kind.push_back(d);
    return same_kind;
  }
  std::vector<DeviceInfo> picked;
  std::size_t start = 0;
  while (start <= spec.size()) {
    const std::size_t comma = std::min(spec.find(',', start), spec.size());
    const std::string selector = spec.substr(start, comma - start);
    if (selector.empty()) throw Error("empty device in '" + spec + "'", "--devices", "e.g. --devices 0,1 or --devices all");
    picked.push_back(select_device(selector));
    start = comma + 1;
  }
  return picked;
}

DeviceInfo rank_device(const std::string& spec, int local_rank) {
  const bool chosen_by_environment = spec.empty() && std::getenv("VOXBREAST_DEVICE");
  const std::vector<DeviceInfo> devices = sweep_devices(spec.empty() && !chosen_by_environment ? "all" : spec);
  return devices[std::size_t(local_rank) % devices.size()];
}

std::vector<std::unique_ptr<ClContext>> open_worker_contexts(const std::string& spec, const MpiWorld& world) {
  std::vector<std::unique_ptr<ClContext>> contexts;
  std::string error;
  try {
    const std::vector<DeviceInfo> devices =
        world.size() > 1 ? std::vector<DeviceInfo>{rank_device(spec, world.local_rank())} : sweep_devices(spec);
    for (const DeviceInfo& d : devices) contexts.push_back(std::make_unique<ClContext>(d));
  } catch (const std::exception& e) {
    error = e.what();
  }
  if (!world.all(error.empty()))
    throw Error(error.empty() ? "another MPI rank could not open its device" : error, "--devices");
  return contexts;
}

std::vector<std::string> worker_names(const std::vector<std::unique_ptr<ClContext>>& contexts) {
  std::vector<std::string> names;
  for (const auto& cl : contexts) names.push_back(std::to_string(cl->info.index) + ": " + cl->info.name);
  return names;
}

}  // namespace vb
