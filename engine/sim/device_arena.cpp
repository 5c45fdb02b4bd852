#include "engine/sim/device_arena.hpp"

#include <algorithm>
#include <cstring>
#include <string>

#include "engine/error.hpp"
#include "engine/sim/opencl_runtime.hpp"

namespace vb {

std::size_t DeviceArena::add(const void* data, std::size_t bytes) {
  require(!buffer_(), "device arena: an array was added after the buffer was created");
  const std::size_t offset = (total_bytes_ + kUnit - 1) / kUnit * kUnit;
  const std::size_t size = std::max<std::size_t>(bytes, 1);
  staging_.resize(offset + size, 0);
  if (data) std::memcpy(staging_.data() + offset, data, bytes);
  offsets_.push_back(offset);
  sizes_.push_back(size);
  total_bytes_ = offset + size;
  return offsets_.size() - 1;
}

void DeviceArena::create(const ClContext& cl) {
  const std::size_t align = cl.info.device.getInfo<CL_DEVICE_MEM_BASE_ADDR_ALIGN>() / 8;
  require(align > 0 && kUnit % align == 0, "device '" + cl.info.name + "' aligns sub-buffers to " +
                                               std::to_string(align) + " bytes, which does not divide " +
                                               std::to_string(kUnit));
  buffer_ = cl::Buffer(cl.context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, total_bytes_, staging_.data());
  for (std::size_t i = 0; i < offsets_.size(); ++i) {
    const cl_buffer_region region = {offsets_[i], sizes_[i]};
    parts_.push_back(buffer_.createSubBuffer(CL_MEM_READ_WRITE, CL_BUFFER_CREATE_TYPE_REGION, &region));
  }
  staging_ = {};
}

cl_uint DeviceArena::offset_units_of(const cl::Buffer& part) const {
  for (std::size_t i = 0; i < parts_.size(); ++i)
    if (parts_[i]() == part()) return offset_units(i);
  throw Error("device arena: the buffer is not one of its arrays");
}

}  // namespace vb
