#include "apps/program_cache_folder.hpp"

#include <cstdlib>

#include "engine/sim/program_cache.hpp"

namespace vb::app {

const std::filesystem::path& program_cache_folder() {
  static const std::filesystem::path folder =
      default_program_cache_dir(std::getenv("VOXBREAST_CACHE_DIR"), std::getenv("XDG_CACHE_HOME"), std::getenv("HOME"));
  return folder;
}

}  // namespace vb::app
