#include "engine/sim/step_work_group.hpp"

#include <charconv>
#include <cstring>
#include <string>

#include "engine/error.hpp"

namespace vb {

std::size_t step_work_group_override(const char* text, std::size_t device_max) {
  std::size_t size = 0;
  const char* end = text + std::strlen(text);
  const auto [last, ec] = std::from_chars(text, end, size);
  require(ec == std::errc() && last == end && size >= 32 && size % 32 == 0 && size <= device_max,
          "VOXBREAST_STEP_WG is '" + std::string(text) + "': the stepping kernels' work-group size must be a multiple of "
              "32 from 32 to " + std::to_string(device_max) + " (this device's largest work-group)",
          "VOXBREAST_STEP_WG", "unset it to take the default (128, or 256 from 131,072 elements)");
  return size;
}

}  // namespace vb
