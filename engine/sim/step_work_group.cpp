#include "engine/sim/step_work_group.hpp"

#include <string>

#include "engine/error.hpp"

namespace vb {

std::size_t checked_step_work_group(std::size_t size, std::size_t device_max) {
  require(size >= 32 && size % 32 == 0 && size <= device_max,
          "step_work_group is " + std::to_string(size) + ": the stepping kernels' work-group size must be a multiple of "
              "32 from 32 to " + std::to_string(device_max) + " (this device's largest work-group)",
          "--plan", "leave it out to take the default (128, or 256 from 131,072 elements)");
  return size;
}

}  // namespace vb
