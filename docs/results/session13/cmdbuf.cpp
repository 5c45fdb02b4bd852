// Throwaway: do cl_khr_command_buffer recordings cut the per-launch cost of dependent launches?
// Build: g++ -O2 -std=c++20 cmdbuf.cpp -lOpenCL (headers: opencl-c-headers); run on the device with scripts/gpu_run.sh run.
#define CL_TARGET_OPENCL_VERSION 300
#define CL_ENABLE_BETA_EXTENSIONS
#include <CL/cl.h>
#include <CL/cl_ext.h>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>
#define CK(x) do { cl_int e_ = (x); if (e_ != CL_SUCCESS) { std::printf("%s failed %d line %d\n", #x, e_, __LINE__); std::exit(1);} } while (0)
static const char* src = R"(
kernel void pass(global float4* a, global const float4* b, uint n) {
  uint i = get_global_id(0); if (i >= n) return;
  float4 s = a[i];
  for (int k = 0; k < 4; ++k) s = s * 0.999f + b[(i + 37u * k) % n] * 0.001f;
  a[i] = s;
})";
int main(int argc, char** argv) {
  const cl_uint n = argc > 1 ? std::atoi(argv[1]) : 36000;
  cl_platform_id plat; CK(clGetPlatformIDs(1, &plat, nullptr));
  cl_device_id dev; CK(clGetDeviceIDs(plat, CL_DEVICE_TYPE_ALL, 1, &dev, nullptr));
  char name[256]; clGetDeviceInfo(dev, CL_DEVICE_NAME, sizeof name, name, nullptr);
  size_t sz = 0; clGetDeviceInfo(dev, CL_DEVICE_EXTENSIONS, 0, nullptr, &sz);
  std::string ext(sz, '\0'); clGetDeviceInfo(dev, CL_DEVICE_EXTENSIONS, sz, ext.data(), nullptr);
  std::printf("device %s\nextensions %s\n", name, ext.c_str());
  cl_int err;
  cl_context ctx = clCreateContext(nullptr, 1, &dev, nullptr, nullptr, &err); CK(err);
  cl_command_queue q = clCreateCommandQueueWithProperties(ctx, dev, nullptr, &err); CK(err);
  cl_program p = clCreateProgramWithSource(ctx, 1, &src, nullptr, &err); CK(err);
  CK(clBuildProgram(p, 1, &dev, "", nullptr, nullptr));
  cl_kernel k = clCreateKernel(p, "pass", &err); CK(err);
  cl_mem a = clCreateBuffer(ctx, CL_MEM_READ_WRITE, 16 * n, nullptr, &err); CK(err);
  cl_mem b = clCreateBuffer(ctx, CL_MEM_READ_WRITE, 16 * n, nullptr, &err); CK(err);
  float zero = 0; CK(clEnqueueFillBuffer(q, a, &zero, 4, 0, 16 * n, 0, nullptr, nullptr));
  CK(clEnqueueFillBuffer(q, b, &zero, 4, 0, 16 * n, 0, nullptr, nullptr));
  CK(clSetKernelArg(k, 0, sizeof a, &a)); CK(clSetKernelArg(k, 1, sizeof b, &b)); CK(clSetKernelArg(k, 2, 4, &n));
  const size_t local = 128, global = (n + 127) / 128 * 128;
  const int per_step = 6, steps = 20000;
  using clk = std::chrono::steady_clock;
  auto launches = [&] {
    CK(clFinish(q)); auto t = clk::now();
    for (int s = 0; s < steps; ++s)
      for (int l = 0; l < per_step; ++l) CK(clEnqueueNDRangeKernel(q, k, 1, nullptr, &global, &local, 0, nullptr, nullptr));
    CK(clFinish(q));
    return std::chrono::duration<double>(clk::now() - t).count() / steps * 1e6;
  };
  std::printf("launches: %.2f us per step of %d\n", launches(), per_step);
  std::printf("launches: %.2f us per step of %d\n", launches(), per_step);
  if (ext.find("cl_khr_command_buffer") == std::string::npos) { std::printf("no cl_khr_command_buffer\n"); return 0; }
  size_t vsz = 0; clGetDeviceInfo(dev, CL_DEVICE_EXTENSIONS_WITH_VERSION, 0, nullptr, &vsz);
  std::vector<cl_name_version> v(vsz / sizeof(cl_name_version));
  clGetDeviceInfo(dev, CL_DEVICE_EXTENSIONS_WITH_VERSION, vsz, v.data(), nullptr);
  for (auto& e : v) if (std::string(e.name).find("command_buffer") != std::string::npos)
    std::printf("%s version %u.%u.%u\n", e.name, CL_VERSION_MAJOR(e.version), CL_VERSION_MINOR(e.version), CL_VERSION_PATCH(e.version));
  auto create = (clCreateCommandBufferKHR_fn)clGetExtensionFunctionAddressForPlatform(plat, "clCreateCommandBufferKHR");
  auto record = (clCommandNDRangeKernelKHR_fn)clGetExtensionFunctionAddressForPlatform(plat, "clCommandNDRangeKernelKHR");
  auto finalize = (clFinalizeCommandBufferKHR_fn)clGetExtensionFunctionAddressForPlatform(plat, "clFinalizeCommandBufferKHR");
  auto enqueue = (clEnqueueCommandBufferKHR_fn)clGetExtensionFunctionAddressForPlatform(plat, "clEnqueueCommandBufferKHR");
  if (!create || !record || !finalize || !enqueue) { std::printf("entry points missing\n"); return 0; }
  cl_device_command_buffer_capabilities_khr caps = 0;
  clGetDeviceInfo(dev, CL_DEVICE_COMMAND_BUFFER_CAPABILITIES_KHR, sizeof caps, &caps, nullptr);
  const bool simultaneous = caps & CL_COMMAND_BUFFER_CAPABILITY_SIMULTANEOUS_USE_KHR;
  std::printf("capabilities 0x%llx simultaneous %d\n", (unsigned long long)caps, int(simultaneous));
  for (int per_buffer : {1, 10, 100}) {
    cl_command_buffer_properties_khr props[] = {CL_COMMAND_BUFFER_FLAGS_KHR, CL_COMMAND_BUFFER_SIMULTANEOUS_USE_KHR, 0};
    cl_command_buffer_khr cb = create(1, &q, simultaneous ? props : nullptr, &err); CK(err);
    for (int s = 0; s < per_buffer; ++s)
      for (int l = 0; l < per_step; ++l) CK(record(cb, nullptr, nullptr, k, 1, nullptr, &global, &local, 0, nullptr, nullptr, nullptr));
    CK(finalize(cb));
    for (int round = 0; round < 2; ++round) {
      int waits = 0;
      CK(clFinish(q)); auto t = clk::now();
      for (int s = 0; s < steps / per_buffer; ++s) {
        cl_int e2 = enqueue(0, nullptr, cb, 0, nullptr, nullptr);
        if (e2 == CL_INVALID_OPERATION) { CK(clFinish(q)); CK(enqueue(0, nullptr, cb, 0, nullptr, nullptr)); ++waits; }
        else CK(e2);
      }
      CK(clFinish(q));
      std::printf("command buffer of %d steps: %.2f us per step\n", per_buffer,
                  std::chrono::duration<double>(clk::now() - t).count() / (steps / per_buffer * per_buffer) * 1e6);
      std::printf("  (host waited for the previous run %d times)\n", waits);
    }
  }
  // the same checksum both ways? (the kernel is deterministic: compare a after equal counts)
  return 0;
}
