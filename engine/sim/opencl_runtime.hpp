#pragma once
/// OpenCL devices and programs: enumeration, selection, and one checked program builder.
#include <CL/opencl.hpp>
#include <cstdint>
#include <string>
#include <vector>

namespace vb {

struct DeviceInfo {
  int index = -1;  ///< position in list_devices()
  std::string platform, name, vendor, version, driver;
  bool is_gpu = false;
  bool fp64 = false;
  std::uint64_t global_memory_bytes = 0;
  std::uint64_t max_allocation_bytes = 0;
  unsigned compute_units = 0;
  /// work-items that execute in lockstep (NVIDIA's warp, AMD's wavefront; 64 for other GPUs, 1
  /// for CPUs): a branch taken differently inside such a group runs both sides
  unsigned simd_width = 1;
  cl::Device device;
};

/// Every device of every platform, GPUs and CPUs alike. Throws vb::Error when there is none.
std::vector<DeviceInfo> list_devices();

/// Picks a device: selector "" uses $VOXBREAST_DEVICE, then the default (first GPU, else first
/// device). "gpu" / "cpu" pick the first of that type, a number picks by index, any other text
/// the first device whose platform or name contains it (case-insensitive).
DeviceInfo select_device(const std::string& selector);

/// A context and in-order queue on one device; `profiling` records kernel times (voxbreast bench
/// --profile).
struct ClContext {
  DeviceInfo info;
  cl::Context context;
  cl::CommandQueue queue;
  bool profiling = false;
  explicit ClContext(const DeviceInfo& device, bool profiling = false);
};

/// Builds a program from embedded kernel files (names as in kernels/, e.g. "common.cl"), in
/// order, after `prelude_front` (inserted after the first file). Each file keeps its own line
/// numbers in compiler messages. On failure throws vb::Error carrying the build log. When
/// $VOXBREAST_DUMP_KERNELS names a folder, the final source and options are written there, and
/// per build the device binary (PTX on NVIDIA) and the build log (with
/// VOXBREAST_CL_OPTIONS=-cl-nv-verbose: registers and spills per kernel).
/// Programs are cached per context and (source, options) for the life of the process.
cl::Program build_program(const ClContext& cl, const std::vector<std::string>& files,
                          const std::string& prelude_after_first, const std::string& options);

/// Text of an embedded kernel file (throws when unknown).
const char* embedded_kernel(const std::string& file_name);

/// Name of an OpenCL status code, e.g. "CL_OUT_OF_RESOURCES".
std::string cl_status_name(int status);

}  // namespace vb
