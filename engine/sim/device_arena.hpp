#pragma once
/// Several device arrays in one OpenCL buffer, each at an offset aligned for sub-buffers.
///
/// Why: NVIDIA's OpenCL spends about 0.4 µs of host time per buffer argument of every launch
/// (2 buffers: ~5 µs per launch; 28: ~14 µs; measured on an H200, docs/PERFORMANCE.md, "State layout and the arena").
/// A 36k-element step's kernels take less than that, so the host's launches set the pace. Kernels
/// take the one buffer and the arrays' offsets (`uint8`/`uint4` arguments, in units of kUnit
/// bytes, -DVB_ARENA_UNIT); the host keeps a sub-buffer per array for its own reads and writes.
#include <CL/opencl.hpp>
#include <cstddef>
#include <vector>

namespace vb {

struct ClContext;

class DeviceArena {
 public:
  /// Offsets are multiples of this, which every device's sub-buffer alignment divides (NVIDIA
  /// 4096 bits = 512 B, PoCL 1024 bits = 128 B; create() checks).
  static constexpr std::size_t kUnit = 4096;

  /// Adds an array of `bytes` bytes, copied from `data` (zeros when null); returns its index.
  std::size_t add(const void* data, std::size_t bytes);
  /// Allocates the buffer (read-write: kernels write some arrays) and one sub-buffer per array.
  void create(const ClContext& cl);

  const cl::Buffer& buffer() const { return buffer_; }
  const cl::Buffer& part(std::size_t i) const { return parts_.at(i); }
  /// Offset of array i in units of kUnit bytes (what kernels take).
  cl_uint offset_units(std::size_t i) const { return cl_uint(offsets_.at(i) / kUnit); }
  /// The same for the array whose sub-buffer is `part` (throws if it is none of them).
  cl_uint offset_units_of(const cl::Buffer& part) const;
  std::size_t bytes() const { return total_bytes_; }

 private:
  std::vector<std::size_t> offsets_, sizes_;
  std::vector<unsigned char> staging_;  // the arrays' initial contents, freed by create()
  std::size_t total_bytes_ = 0;
  cl::Buffer buffer_;
  std::vector<cl::Buffer> parts_;
};

}  // namespace vb
