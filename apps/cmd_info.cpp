// voxbreast info — lists OpenCL platforms and devices (memory, fp64), which one is the default, and
// the program cache folder with its size.
#include <cstdio>

#include "apps/commands.hpp"
#include "apps/program_cache_folder.hpp"
#include "engine/sim/opencl_runtime.hpp"
#include "engine/sim/program_cache.hpp"

namespace vb::app {

Command add_info(CLI::App& app) {
  auto* sub = app.add_subcommand("info", "List OpenCL devices (memory, fp64 support)");
  return {sub, [] {
    const auto devices = list_devices();
    const DeviceInfo chosen = select_device("");
    for (const auto& d : devices) {
      std::printf("%c %d: %s — %s\n", d.index == chosen.index ? '*' : ' ', d.index, d.platform.c_str(), d.name.c_str());
      std::printf("     type %s, %u compute units, %.2f GiB global memory (max buffer %.2f GiB), fp64 %s\n",
                  d.is_gpu ? "GPU" : "CPU/other", d.compute_units, double(d.global_memory_bytes) / (1 << 30),
                  double(d.max_allocation_bytes) / (1 << 30), d.fp64 ? "yes" : "no");
      std::printf("     %s, driver %s\n", d.version.c_str(), d.driver.c_str());
    }
    std::printf("* = default device (choose with --device or VOXBREAST_DEVICE=gpu|cpu|N|name)\n");
    if (const auto& cache = program_cache_folder(); !cache.empty()) {
      const ProgramCacheUsage usage = program_cache_usage(cache);
      std::printf("program cache: %s, %zu programs, %.1f MiB (voxbreast cache --clear empties it)\n",
                  cache.string().c_str(), usage.entries, double(usage.bytes) / (1 << 20));
    } else {
      std::printf("program cache: off\n");
    }
    return 0;
  }};
}

}  // namespace vb::app
