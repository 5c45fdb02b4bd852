// Every test binary keeps built OpenCL programs where the app would (VOXBREAST_CACHE_DIR, else the
// user's cache folder; scripts/test.sh sets one inside the build folder), read once at start-up.
#include <cstdlib>

#include "engine/sim/program_cache.hpp"

namespace {

const bool program_cache_set = [] {
  vb::set_program_cache_dir(vb::default_program_cache_dir(std::getenv("VOXBREAST_CACHE_DIR"),
                                                          std::getenv("XDG_CACHE_HOME"), std::getenv("HOME")));
  return true;
}();

}  // namespace
