#include "engine/sim/opencl_runtime.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <optional>

#include <CL/cl_ext.h>

#include "engine/error.hpp"
#include "engine/sim/program_cache.hpp"

namespace vb::kernels {
const std::vector<std::pair<const char*, const char*>>& embedded_sources();
}

namespace vb {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\0' || std::isspace(static_cast<unsigned char>(s.back())))) s.pop_back();
  return s;
}

/// The vendor's own query where the device has it (cl_nv_device_attribute_query,
/// cl_amd_device_attribute_query); 64, a multiple of both, for other GPUs; 1 for CPUs.
unsigned simd_width(const cl::Device& d, bool is_gpu) {
  if (!is_gpu) return 1;
  const std::string extensions = d.getInfo<CL_DEVICE_EXTENSIONS>();
  const auto query = [&](cl_device_info what) {
    cl_uint width = 0;
    return clGetDeviceInfo(d(), what, sizeof width, &width, nullptr) == CL_SUCCESS && width > 0 ? unsigned(width) : 64u;
  };
  if (extensions.find("cl_nv_device_attribute_query") != std::string::npos) return query(CL_DEVICE_WARP_SIZE_NV);
  if (extensions.find("cl_amd_device_attribute_query") != std::string::npos) return query(CL_DEVICE_WAVEFRONT_WIDTH_AMD);
  return 64;
}

DeviceInfo describe(const cl::Platform& platform, const cl::Device& d, int index) {
  DeviceInfo info;
  info.index = index;
  info.device = d;
  info.platform = trim(platform.getInfo<CL_PLATFORM_NAME>());
  info.name = trim(d.getInfo<CL_DEVICE_NAME>());
  info.vendor = trim(d.getInfo<CL_DEVICE_VENDOR>());
  info.version = trim(d.getInfo<CL_DEVICE_VERSION>());
  info.driver = trim(d.getInfo<CL_DRIVER_VERSION>());
  info.is_gpu = (d.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_GPU) != 0;
  info.fp64 = d.getInfo<CL_DEVICE_DOUBLE_FP_CONFIG>() != 0;
  info.global_memory_bytes = d.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
  info.max_allocation_bytes = d.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
  info.compute_units = d.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
  info.simd_width = simd_width(d, info.is_gpu);
  return info;
}

}  // namespace

std::vector<DeviceInfo> list_devices() {
  std::vector<cl::Platform> platforms;
  // clGetPlatformIDs reports CL_PLATFORM_NOT_FOUND_KHR (-1001) when no ICD is installed.
  cl_uint count = 0;
  const cl_int status = clGetPlatformIDs(0, nullptr, &count);
  require(status == CL_SUCCESS && count > 0,
          "no OpenCL platform found (status " + cl_status_name(status) + ")", "OpenCL",
          "install an OpenCL driver, e.g. pocl-opencl-icd (scripts/setup.sh does)");
  cl::Platform::get(&platforms);
  std::vector<DeviceInfo> out;
  for (const auto& p : platforms) {
    std::vector<cl::Device> devices;
    try {
      p.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;  // a platform with no devices is not an error
    }
    for (const auto& d : devices) out.push_back(describe(p, d, int(out.size())));
  }
  require(!out.empty(), "no OpenCL device found", "OpenCL", "install an OpenCL driver");
  return out;
}

DeviceInfo select_device(const std::string& selector_in) {
  std::string selector = selector_in;
  if (selector.empty())
    if (const char* env = std::getenv("VOXBREAST_DEVICE")) selector = env;
  const auto devices = list_devices();
  const std::string sel = lower(selector);
  auto first = [&](const std::function<bool(const DeviceInfo&)>& pred) -> const DeviceInfo* {
    auto it = std::find_if(devices.begin(), devices.end(), pred);
    return it == devices.end() ? nullptr : &*it;
  };
  const DeviceInfo* pick = nullptr;
  if (sel.empty()) {
    pick = first([](const DeviceInfo& d) { return d.is_gpu; });
    if (!pick) pick = &devices.front();
  } else if (sel == "gpu" || sel == "cpu") {
    const bool gpu = sel == "gpu";
    pick = first([&](const DeviceInfo& d) { return d.is_gpu == gpu; });
  } else if (std::all_of(sel.begin(), sel.end(), ::isdigit)) {
    const int index = std::stoi(sel);
    if (index < int(devices.size())) pick = &devices[index];
  } else {
    pick = first([&](const DeviceInfo& d) {
      return lower(d.name).find(sel) != std::string::npos ||
             lower(d.platform).find(sel) != std::string::npos;
    });
  }
  if (!pick) {
    std::string names;
    for (const auto& d : devices) names += (names.empty() ? "" : ", ") + std::to_string(d.index) + ": " + d.name;
    throw Error("no OpenCL device matches '" + selector + "'", "--device / VOXBREAST_DEVICE",
                "available: " + names);
  }
  return *pick;
}

namespace {

/// Everything a built binary depends on: a change to any of it (a new driver, other options, an
/// edited kernel) names another cache entry.
std::string program_cache_key(const DeviceInfo& d, const std::string& source, const std::string& build_options) {
  const std::string platform_version = trim(cl::Platform(d.device.getInfo<CL_DEVICE_PLATFORM>()).getInfo<CL_PLATFORM_VERSION>());
  return "platform: " + d.platform + " / " + platform_version + "\ndevice: " + d.name + " / " + d.vendor + " / " +
         d.version + "\ndriver: " + d.driver + "\noptions: " + build_options + "\nsource:\n" + source;
}

/// The program rebuilt from a cached binary; none when the entry is missing, damaged, or refused by
/// the driver (which then builds from source and replaces the entry).
std::optional<cl::Program> load_cached_program(const ClContext& cl, const std::filesystem::path& dir,
                                               const std::string& key, const std::string& build_options) {
  const auto binary = read_program_cache(dir, key);
  if (!binary) return std::nullopt;
  try {
    cl::Program program(cl.context, {cl.info.device}, cl::Program::Binaries{*binary});
    program.build({cl.info.device}, build_options.c_str());
    return program;
  } catch (const cl::Error&) {
    return std::nullopt;
  }
}

}  // namespace

ClContext::ClContext(const DeviceInfo& device, bool profiling)
    : info(device),
      context(device.device),
      queue(context, device.device, profiling ? cl_command_queue_properties(CL_QUEUE_PROFILING_ENABLE) : 0),
      profiling(profiling) {}

const char* embedded_kernel(const std::string& file_name) {
  for (const auto& [name, text] : kernels::embedded_sources())
    if (file_name == name) return text;
  throw Error("no embedded kernel named '" + file_name + "'");
}

cl::Program build_program(const ClContext& cl, const std::vector<std::string>& files,
                          const std::string& prelude_after_first, const std::string& options) {
  std::string source;
  for (std::size_t i = 0; i < files.size(); ++i) {
    source += "#line 1 \"kernels/" + files[i] + "\"\n";
    source += embedded_kernel(files[i]);
    source += "\n";
    if (i == 0 && !prelude_after_first.empty()) source += "#line 1 \"generated\"\n" + prelude_after_first;
  }
  if (const char* dir = std::getenv("VOXBREAST_DUMP_KERNELS")) {
    std::filesystem::create_directories(dir);
    std::ofstream(std::filesystem::path(dir) / "program.cl") << "// options: " << options << "\n" << source;
  }
  // Built programs are kept per context for the process: a fit builds one Simulator per forward
  // solve with the same source and options (docs/FIT.md). A cached program retains its context,
  // so a context's address is never reused while its entry exists.
  static std::mutex cache_mutex;
  static std::map<std::pair<cl_context, std::string>, cl::Program> cache;
  const std::pair<cl_context, std::string> key{cl.context(), options + "\n" + source};
  {
    const std::lock_guard<std::mutex> lock(cache_mutex);
    if (const auto it = cache.find(key); it != cache.end()) return it->second;
  }
  std::string build_options = options;
  if (const char* extra = std::getenv("VOXBREAST_CL_OPTIONS")) build_options += std::string(" ") + extra;
  const std::filesystem::path disk = std::getenv("VOXBREAST_DUMP_KERNELS") ? std::filesystem::path() : program_cache_dir();
  const bool use_disk = !disk.empty();
  const std::string disk_key = use_disk ? program_cache_key(cl.info, source, build_options) : std::string();
  if (use_disk)
    if (auto cached = load_cached_program(cl, disk, disk_key, build_options)) {
      const std::lock_guard<std::mutex> lock(cache_mutex);
      return cache.emplace(key, *cached).first->second;
    }
  cl::Program program(cl.context, source);
  try {
    program.build({cl.info.device}, build_options.c_str());
    if (const char* dir = std::getenv("VOXBREAST_DUMP_KERNELS")) {
      // the device's binary (PTX on NVIDIA) and build log, named by the options' hash
      const std::string stem =
          (std::filesystem::path(dir) / ("program_" + std::to_string(std::hash<std::string>{}(build_options)))).string();
      std::ofstream(stem + ".log") << build_options << "\n" << program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(cl.info.device);
      const auto binaries = program.getInfo<CL_PROGRAM_BINARIES>();
      if (!binaries.empty())
        std::ofstream(stem + ".bin", std::ios::binary)
            .write(reinterpret_cast<const char*>(binaries[0].data()), std::streamsize(binaries[0].size()));
    }
  } catch (const cl::Error& e) {
    std::string log;
    try {
      log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(cl.info.device);
    } catch (const cl::Error&) {
      log = "(no build log available)";
    }
    throw Error("OpenCL kernel build failed (" + cl_status_name(e.err()) + ") with options '" + options +
                    "':\n" + trim(log),
                cl.info.name, "set VOXBREAST_DUMP_KERNELS=DIR to write the full source");
  }
  if (use_disk) {
    const auto binaries = program.getInfo<CL_PROGRAM_BINARIES>();
    if (binaries.size() == 1 && !binaries[0].empty()) write_program_cache(disk, disk_key, binaries[0]);
  }
  const std::lock_guard<std::mutex> lock(cache_mutex);
  cache.emplace(key, program);
  return program;
}

std::string cl_status_name(int status) {
  switch (status) {
#define VB_CASE(x) \
  case x:          \
    return #x;
    VB_CASE(CL_SUCCESS)
    VB_CASE(CL_DEVICE_NOT_FOUND)
    VB_CASE(CL_DEVICE_NOT_AVAILABLE)
    VB_CASE(CL_COMPILER_NOT_AVAILABLE)
    VB_CASE(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    VB_CASE(CL_OUT_OF_RESOURCES)
    VB_CASE(CL_OUT_OF_HOST_MEMORY)
    VB_CASE(CL_BUILD_PROGRAM_FAILURE)
    VB_CASE(CL_INVALID_VALUE)
    VB_CASE(CL_INVALID_DEVICE)
    VB_CASE(CL_INVALID_CONTEXT)
    VB_CASE(CL_INVALID_COMMAND_QUEUE)
    VB_CASE(CL_INVALID_MEM_OBJECT)
    VB_CASE(CL_INVALID_BUILD_OPTIONS)
    VB_CASE(CL_INVALID_PROGRAM)
    VB_CASE(CL_INVALID_PROGRAM_EXECUTABLE)
    VB_CASE(CL_INVALID_KERNEL_NAME)
    VB_CASE(CL_INVALID_KERNEL)
    VB_CASE(CL_INVALID_ARG_INDEX)
    VB_CASE(CL_INVALID_ARG_VALUE)
    VB_CASE(CL_INVALID_ARG_SIZE)
    VB_CASE(CL_INVALID_KERNEL_ARGS)
    VB_CASE(CL_INVALID_WORK_GROUP_SIZE)
    VB_CASE(CL_INVALID_WORK_ITEM_SIZE)
    VB_CASE(CL_INVALID_GLOBAL_OFFSET)
    VB_CASE(CL_INVALID_BUFFER_SIZE)
    VB_CASE(CL_INVALID_GLOBAL_WORK_SIZE)
#undef VB_CASE
    case -1001:
      return "CL_PLATFORM_NOT_FOUND_KHR";
    default:
      return "OpenCL status " + std::to_string(status);
  }
}

}  // namespace vb
