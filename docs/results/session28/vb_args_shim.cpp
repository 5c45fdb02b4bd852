// Session 28 (docs/PERF_NOTES.md, "Session 28"): an LD_PRELOAD shim on the OpenCL ICD loader
// that records main's kernel arguments and, at heun_predict's VBSHIM_AT-th launch (default 300),
// writes both stepping kernels' arguments and every buffer they take to VBSHIM_DIR, so that
// main_host.cpp can run main's own PTX under Nsight Compute (which does not see OpenCL launches).
// A diagnostic only, outside the build.
//   g++ -O2 -shared -fPIC vb_args_shim.cpp -o vb_args_shim.so -ldl
//   VBSHIM_DIR=/tmp/args LD_PRELOAD=./vb_args_shim.so voxbreast bench --device gpu --quick --no-study --sizes 115
#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>
#include <dlfcn.h>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

namespace {
std::map<cl_mem, size_t> buffers;
std::map<cl_kernel, std::string> names;
std::map<cl_kernel, std::map<cl_uint, std::vector<unsigned char>>> args;
int predict_launches = 0;
bool dumped = false;

template <class F> F real(const char* name) { return reinterpret_cast<F>(dlsym(RTLD_NEXT, name)); }

void dump(cl_command_queue q, const size_t* global, const size_t* local) {
  const char* dir = std::getenv("VBSHIM_DIR");
  if (!dir) return;
  clFinish(q);
  const std::string manifest = std::string(dir) + "/manifest.txt";
  FILE* m = std::fopen(manifest.c_str(), "w");
  if (!m) { std::perror(manifest.c_str()); return; }
  std::map<cl_mem, int> ids;
  for (const auto& [k, name] : names) {
    if (name != "heun_predict" && name != "heun_correct") continue;
    const auto& a = args[k];
    std::fprintf(m, "kernel %s %zu %zu %zu\n", name.c_str(), a.size(), global[0], local ? local[0] : 0);
    for (const auto& [i, bytes] : a) {
      cl_mem mem = nullptr;
      if (bytes.size() == sizeof(cl_mem)) std::memcpy(&mem, bytes.data(), sizeof mem);
      if (mem && buffers.count(mem)) {
        if (!ids.count(mem)) {
          const int id = int(ids.size());
          ids[mem] = id;
          std::vector<unsigned char> data(buffers[mem]);
          clEnqueueReadBuffer(q, mem, CL_TRUE, 0, data.size(), data.data(), 0, nullptr, nullptr);
          const std::string path = std::string(dir) + "/buf" + std::to_string(id) + ".bin";
          FILE* f = std::fopen(path.c_str(), "wb");
          std::fwrite(data.data(), 1, data.size(), f);
          std::fclose(f);
        }
        std::fprintf(m, "arg %u buf %d %zu\n", i, ids[mem], buffers[mem]);
      } else {
        std::fprintf(m, "arg %u val %zu", i, bytes.size());
        for (unsigned char b : bytes) std::fprintf(m, " %02x", b);
        std::fprintf(m, "\n");
      }
    }
  }
  std::fclose(m);
  std::fprintf(stderr, "vb_args_shim: wrote %s\n", manifest.c_str());
}
}  // namespace

extern "C" {
cl_mem clCreateBuffer(cl_context c, cl_mem_flags f, size_t size, void* host, cl_int* err) {
  static auto fn = real<decltype(&clCreateBuffer)>("clCreateBuffer");
  cl_mem mem = fn(c, f, size, host, err);
  if (mem) buffers[mem] = size;
  return mem;
}
cl_kernel clCreateKernel(cl_program p, const char* name, cl_int* err) {
  static auto fn = real<decltype(&clCreateKernel)>("clCreateKernel");
  cl_kernel k = fn(p, name, err);
  if (k) names[k] = name;
  return k;
}
cl_int clSetKernelArg(cl_kernel k, cl_uint i, size_t size, const void* value) {
  static auto fn = real<decltype(&clSetKernelArg)>("clSetKernelArg");
  if (value) args[k][i].assign(static_cast<const unsigned char*>(value), static_cast<const unsigned char*>(value) + size);
  return fn(k, i, size, value);
}
cl_int clEnqueueNDRangeKernel(cl_command_queue q, cl_kernel k, cl_uint dim, const size_t* offset, const size_t* global,
                              const size_t* local, cl_uint nw, const cl_event* wait, cl_event* ev) {
  static auto fn = real<decltype(&clEnqueueNDRangeKernel)>("clEnqueueNDRangeKernel");
  if (!dumped && names.count(k) && names[k] == "heun_predict") {
    const char* at = std::getenv("VBSHIM_AT");
    if (++predict_launches == (at ? std::atoi(at) : 300)) {
      dump(q, global, local);
      dumped = true;
    }
  }
  return fn(q, k, dim, offset, global, local, nw, wait, ev);
}
}
