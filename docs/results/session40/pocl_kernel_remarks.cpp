// Session 40 (docs/PERF_NOTES.md change 31; not part of the build): compiles one kernel of an
// OpenCL source on the first device (PoCL here) by enqueuing it once with zeroed arguments. PoCL
// builds a kernel's work-group function at its first enqueue, so the vectoriser's remarks are that
// kernel's alone. The source is a program dumped by VOXBREAST_DUMP_KERNELS=DIR (its first line
// holds the build options). Build and run:
//   g++ -O1 -std=c++20 pocl_kernel_remarks.cpp -o remarks -lOpenCL
//   POCL_CACHE_DIR=$(mktemp -d) POCL_VECTORIZER_REMARKS=1 ./remarks DIR/program.cl heun_predict_lanes 2>&1 |
//     sed 's/<unknown>:0:0: /\n/g' | grep -i 'loop' | sort | uniq -c
#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>
int main(int argc, char** argv) {
  if (argc < 3) { std::fprintf(stderr, "usage: harness SOURCE KERNEL [local]\n"); return 2; }
  std::ifstream in(argv[1]); std::stringstream ss; ss << in.rdbuf(); std::string src = ss.str();
  std::string opts; if (src.rfind("// options: ", 0) == 0) opts = src.substr(12, src.find('\n') - 12);
  opts += " -cl-kernel-arg-info";
  size_t local = argc > 3 ? std::atoi(argv[3]) : 256;
  cl_platform_id p; cl_uint np; clGetPlatformIDs(1, &p, &np);
  cl_device_id d; clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 1, &d, nullptr);
  cl_int err; cl_context ctx = clCreateContext(nullptr, 1, &d, nullptr, nullptr, &err);
  cl_command_queue q = clCreateCommandQueue(ctx, d, 0, &err);
  const char* s = src.c_str(); cl_program prog = clCreateProgramWithSource(ctx, 1, &s, nullptr, &err);
  err = clBuildProgram(prog, 1, &d, opts.c_str(), nullptr, nullptr);
  if (err) { size_t n; clGetProgramBuildInfo(prog, d, CL_PROGRAM_BUILD_LOG, 0, nullptr, &n); std::vector<char> l(n);
    clGetProgramBuildInfo(prog, d, CL_PROGRAM_BUILD_LOG, n, l.data(), nullptr); std::fprintf(stderr, "%s\n", l.data()); return 1; }
  cl_kernel k = clCreateKernel(prog, argv[2], &err); if (err) { std::fprintf(stderr, "no kernel %s\n", argv[2]); return 1; }
  cl_uint na; clGetKernelInfo(k, CL_KERNEL_NUM_ARGS, sizeof na, &na, nullptr);
  std::vector<char> zeros(1 << 24, 0);
  cl_mem buf = clCreateBuffer(ctx, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, zeros.size(), zeros.data(), &err);
  for (cl_uint i = 0; i < na; ++i) {
    cl_kernel_arg_address_qualifier aq; clGetKernelArgInfo(k, i, CL_KERNEL_ARG_ADDRESS_QUALIFIER, sizeof aq, &aq, nullptr);
    char tn[256] = {0}; clGetKernelArgInfo(k, i, CL_KERNEL_ARG_TYPE_NAME, sizeof tn, tn, nullptr);
    if (aq == CL_KERNEL_ARG_ADDRESS_GLOBAL || aq == CL_KERNEL_ARG_ADDRESS_CONSTANT) { clSetKernelArg(k, i, sizeof buf, &buf); continue; }
    if (aq == CL_KERNEL_ARG_ADDRESS_LOCAL) { clSetKernelArg(k, i, 4096, nullptr); continue; }
    std::string t = tn; size_t n = 4;
    if (t.find("double") == 0 || t.find("long") == 0 || t.find("ulong") == 0) n = 8;
    size_t w = 1; for (int v : {16, 8, 4, 3, 2}) if (t.size() > std::to_string(v).size() && t.substr(t.size() - std::to_string(v).size()) == std::to_string(v)) { w = v == 3 ? 4 : v; break; }
    char z[128] = {0}; err = clSetKernelArg(k, i, n * w, z);
    if (err) std::fprintf(stderr, "arg %u (%s) size %zu: %d\n", i, tn, n * w, err);
  }
  size_t g = local; err = clEnqueueNDRangeKernel(q, k, 1, nullptr, &g, &local, 0, nullptr, nullptr);
  if (err) std::fprintf(stderr, "enqueue %d\n", err);
  clFinish(q); std::printf("ok %s\n", argv[2]); return 0;
}
