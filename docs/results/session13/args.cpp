// Throwaway: host cost of clEnqueueNDRangeKernel on NVIDIA's OpenCL by kind and number of arguments,
// and whether enqueues of slow kernels block the host (queue depth).
// Build: g++ -O2 -std=c++20 args.cpp -lOpenCL (headers: opencl-c-headers); run on the device with scripts/gpu_run.sh run.
#define CL_TARGET_OPENCL_VERSION 300
#include <CL/cl.h>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>
#define CK(x) do { cl_int e_ = (x); if (e_ != CL_SUCCESS) { std::printf("%s failed %d line %d\n", #x, e_, __LINE__); std::exit(1);} } while (0)
static const char* src = R"(
typedef struct { float4 a[8]; } P;
kernel void b1(global float4* a, uint n) { if (get_global_id(0) == n) a[0] = 0; }
kernel void b1s20(global float4* a, uint n, uint s1, uint s2, uint s3, uint s4, uint s5, uint s6, uint s7, uint s8, uint s9,
  uint s10, uint s11, uint s12, uint s13, uint s14, uint s15, uint s16, uint s17, uint s18, uint s19) {
  if (get_global_id(0) == n) a[0] = s1+s2+s3+s4+s5+s6+s7+s8+s9+s10+s11+s12+s13+s14+s15+s16+s17+s18+s19; }
kernel void b1struct(global float4* a, uint n, P p) { if (get_global_id(0) == n) a[0] = p.a[3]; }
kernel void b1vec(global float4* a, uint n, uint8 at, float4 x, float4 y, float4 z) { if (get_global_id(0) == n) a[at.s3] = x + y + z; }
kernel void b8(global float4* a, global float4* b, global float4* c, global float4* d, global float4* e, global float4* f,
  global float4* g, global float4* h, uint n) { if (get_global_id(0) == n) a[0] = b[0]+c[0]+d[0]+e[0]+f[0]+g[0]+h[0]; }
kernel void slow(global float4* a, uint n) { float4 s = a[get_global_id(0)]; for (uint i = 0; i < n; ++i) s = s * 0.9999f + 0.5f; a[get_global_id(0)] = s; }
)";
using clk = std::chrono::steady_clock;
static double since(clk::time_point t) { return std::chrono::duration<double>(clk::now() - t).count(); }
int main() {
  cl_platform_id plat; CK(clGetPlatformIDs(1, &plat, nullptr));
  cl_device_id dev; CK(clGetDeviceIDs(plat, CL_DEVICE_TYPE_ALL, 1, &dev, nullptr));
  cl_int err;
  cl_context ctx = clCreateContext(nullptr, 1, &dev, nullptr, nullptr, &err); CK(err);
  cl_command_queue q = clCreateCommandQueueWithProperties(ctx, dev, nullptr, &err); CK(err);
  cl_program p = clCreateProgramWithSource(ctx, 1, &src, nullptr, &err); CK(err);
  CK(clBuildProgram(p, 1, &dev, "", nullptr, nullptr));
  std::vector<cl_mem> m(8);
  for (auto& b : m) { b = clCreateBuffer(ctx, CL_MEM_READ_WRITE, 1 << 20, nullptr, &err); CK(err); }
  const cl_uint big = 1u << 30;
  auto kernel = [&](const char* name) { cl_kernel k = clCreateKernel(p, name, &err); CK(err); return k; };
  cl_kernel kb1 = kernel("b1"), ks20 = kernel("b1s20"), kst = kernel("b1struct"), kvec = kernel("b1vec"), kb8 = kernel("b8"), kslow = kernel("slow");
  for (cl_kernel k : {kb1, ks20, kst, kvec}) { CK(clSetKernelArg(k, 0, sizeof(cl_mem), &m[0])); CK(clSetKernelArg(k, 1, 4, &big)); }
  for (int a = 2; a < 21; ++a) CK(clSetKernelArg(ks20, a, 4, &big));
  char blob[128] = {}; CK(clSetKernelArg(kst, 2, 128, blob));
  cl_uint at[8] = {}; float x[4] = {}; CK(clSetKernelArg(kvec, 2, 32, at));
  for (int a = 3; a < 6; ++a) CK(clSetKernelArg(kvec, a, 16, x));
  for (int a = 0; a < 8; ++a) CK(clSetKernelArg(kb8, a, sizeof(cl_mem), &m[a]));
  CK(clSetKernelArg(kb8, 8, 4, &big));
  const size_t g = 36864, l = 128;
  auto host_per_launch = [&](cl_kernel k, int count) {
    CK(clFinish(q));
    auto t = clk::now();
    for (int i = 0; i < count; ++i) CK(clEnqueueNDRangeKernel(q, k, 1, nullptr, &g, &l, 0, nullptr, nullptr));
    double h = since(t) / count;
    CK(clFinish(q));
    return std::make_pair(h * 1e6, since(t) / count * 1e6);
  };
  for (int r = 0; r < 2; ++r) {
    for (auto [name, k] : std::vector<std::pair<const char*, cl_kernel>>{{"1 buffer + uint", kb1}, {"1 buffer + 20 uint", ks20},
         {"1 buffer + uint + 128 B struct", kst}, {"1 buffer + uint + uint8 + 3 float4", kvec}, {"8 buffers + uint", kb8}}) {
      auto a = host_per_launch(k, 16); auto b = host_per_launch(k, 5000);
      std::printf("%-36s 16 launches: host %.2f us each; 5000: host %.2f, total %.2f us each\n", name, a.first, b.first, b.second);
    }
    // set one buffer argument between launches (as the step does)
    CK(clFinish(q)); auto t = clk::now();
    for (int i = 0; i < 5000; ++i) { CK(clSetKernelArg(kb8, i % 8, sizeof(cl_mem), &m[(i + 1) % 8]));
      CK(clEnqueueNDRangeKernel(q, kb8, 1, nullptr, &g, &l, 0, nullptr, nullptr)); }
    std::printf("8 buffers, one setArg before each launch: %.2f us each\n", since(t) / 5000 * 1e6);
    CK(clFinish(q)); t = clk::now();
    for (int i = 0; i < 100000; ++i) CK(clSetKernelArg(kb8, i % 8, sizeof(cl_mem), &m[(i + 1) % 8]));
    std::printf("clSetKernelArg (buffer) alone: %.3f us\n", since(t) / 100000 * 1e6);
    t = clk::now();
    for (int i = 0; i < 100000; ++i) CK(clSetKernelArg(ks20, 2 + i % 19, 4, &big));
    std::printf("clSetKernelArg (uint) alone: %.3f us\n", since(t) / 100000 * 1e6);
  }
  // queue depth: slow kernels (one group, long loop)
  CK(clSetKernelArg(kslow, 0, sizeof(cl_mem), &m[0]));
  cl_uint iters = 200000; CK(clSetKernelArg(kslow, 1, 4, &iters));
  const size_t sg = 128;
  CK(clEnqueueNDRangeKernel(q, kslow, 1, nullptr, &sg, &l, 0, nullptr, nullptr)); CK(clFinish(q));
  auto t = clk::now();
  CK(clEnqueueNDRangeKernel(q, kslow, 1, nullptr, &sg, &l, 0, nullptr, nullptr)); CK(clFinish(q));
  const double one = since(t) * 1e6;
  for (int count : {16, 256, 2048}) {
    CK(clFinish(q)); t = clk::now();
    for (int i = 0; i < count; ++i) CK(clEnqueueNDRangeKernel(q, kslow, 1, nullptr, &sg, &l, 0, nullptr, nullptr));
    const double h = since(t) * 1e6 / count;
    CK(clFinish(q));
    std::printf("slow kernel (%.0f us alone) x %d: host %.2f us per enqueue, total %.2f us each\n", one, count, h, since(t) * 1e6 / count);
  }
  return 0;
}
