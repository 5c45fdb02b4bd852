// voxbreast cache — where built OpenCL programs are kept between runs, their size, and --clear.
//   voxbreast cache            # folder, entries, size
//   voxbreast cache --clear    # delete every entry (the next run of each program builds it again)
#include <cstdio>

#include "apps/commands.hpp"
#include "apps/program_cache_folder.hpp"
#include "engine/sim/program_cache.hpp"

namespace vb::app {

Command add_cache(CLI::App& app) {
  auto* sub = app.add_subcommand("cache", "Show or clear the on-disk cache of built OpenCL programs");
  static bool clear = false;
  sub->add_flag("--clear", clear, "Delete every cached program");
  return {sub, [] {
    const auto& folder = program_cache_folder();
    if (folder.empty()) {
      std::printf("program cache: off (VOXBREAST_CACHE_DIR=off or no home folder)\n");
      return 0;
    }
    if (clear) {
      const std::size_t removed = clear_program_cache(folder);
      std::printf("program cache %s: removed %zu files\n", folder.string().c_str(), removed);
      return 0;
    }
    const ProgramCacheUsage usage = program_cache_usage(folder);
    std::printf("program cache %s: %zu programs, %.1f MiB (VOXBREAST_CACHE_DIR sets the folder, 'off' disables it)\n",
                folder.string().c_str(), usage.entries, double(usage.bytes) / (1 << 20));
    return 0;
  }};
}

}  // namespace vb::app
