#pragma once
/// Where this process keeps built OpenCL programs between runs (engine/sim/program_cache.hpp).
#include <filesystem>

namespace vb::app {

/// $VOXBREAST_CACHE_DIR, else $XDG_CACHE_HOME/voxbreast, else ~/.cache/voxbreast, read once per
/// process; empty (no disk cache) when VOXBREAST_CACHE_DIR is "off" or no home folder is known.
const std::filesystem::path& program_cache_folder();

}  // namespace vb::app
