// Session 28 (docs/PERF_NOTES.md, "Session 28"): runs main's own heun_predict and heun_correct,
// from the PTX NVIDIA's OpenCL compiler produced (VOXBREAST_DUMP_KERNELS), through the CUDA driver
// API with the arguments and buffers vb_args_shim.cpp recorded from a bench run, so that Nsight
// Compute can profile main's stepping kernels as session 27's ncu_host.cpp does the prototype's.
// A diagnostic only, outside the build.
//   nvcc -O2 -o main_host main_host.cpp -lcuda
//   ncu --set full --launch-skip 4 --launch-count 2 ./main_host program.bin ARGS_DIR STEPS
#include <cuda.h>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#define CK(x) do { CUresult r_ = (x); if (r_ != CUDA_SUCCESS) { const char* m_; cuGetErrorString(r_, &m_); std::fprintf(stderr, "%s: %s\n", #x, m_); std::exit(1); } } while (0)

struct Kernel {
  std::string name;
  size_t global = 0, local = 0;
  std::vector<std::vector<unsigned char>> params;  // each parameter's bytes (buffers: a device pointer)
  std::vector<void*> pointers;
};

int main(int argc, char** argv) {
  if (argc < 4) { std::fprintf(stderr, "usage: main_host program.bin ARGS_DIR STEPS\n"); return 2; }
  const std::string dir = argv[2];
  const int steps = std::atoi(argv[3]);
  CK(cuInit(0)); CUdevice dev; CK(cuDeviceGet(&dev, 0)); CUcontext ctx; CK(cuCtxCreate(&ctx, nullptr, 0, dev));
  std::string ptx;
  { std::ifstream f(argv[1], std::ios::binary); std::stringstream ss; ss << f.rdbuf(); ptx = ss.str(); }
  ptx = ptx.substr(0, ptx.find('\0'));
  // OpenCL's global offset (%envreg3) is zero here; CUDA's JIT refuses OpenCL's texture mode
  ptx = std::regex_replace(std::regex_replace(ptx, std::regex("%envreg3"), "0"), std::regex(", texmode_independent"), "");
  char log[8192] = {0};
  CUjit_option opt[] = {CU_JIT_ERROR_LOG_BUFFER, CU_JIT_ERROR_LOG_BUFFER_SIZE_BYTES};
  void* val[] = {log, (void*)(size_t)sizeof log};
  CUmodule mod;
  const CUresult r = cuModuleLoadDataEx(&mod, ptx.c_str(), 2, opt, val);
  if (r != CUDA_SUCCESS) std::fprintf(stderr, "JIT log: %s\n", log);
  CK(r);

  std::map<int, CUdeviceptr> bufs;
  std::vector<Kernel> ks;
  std::ifstream m(dir + "/manifest.txt");
  for (std::string line; std::getline(m, line);) {
    std::istringstream ls(line);
    std::string what; ls >> what;
    if (what == "kernel") {
      Kernel k; size_t nargs; ls >> k.name >> nargs >> k.global >> k.local;
      if (k.local == 0) k.local = 256;
      k.params.resize(nargs);
      ks.push_back(k);
    } else if (what == "arg") {
      unsigned i; std::string kind; ls >> i >> kind;
      auto& p = ks.back().params.at(i);
      if (kind == "buf") {
        int id; size_t size; ls >> id >> size;
        if (!bufs.count(id)) {
          std::ifstream f(dir + "/buf" + std::to_string(id) + ".bin", std::ios::binary);
          std::vector<char> data(size);
          f.read(data.data(), std::streamsize(size));
          CUdeviceptr d; CK(cuMemAlloc(&d, size)); CK(cuMemcpyHtoD(d, data.data(), size));
          bufs[id] = d;
        }
        p.resize(sizeof(CUdeviceptr));
        std::memcpy(p.data(), &bufs[id], sizeof(CUdeviceptr));
      } else {
        size_t n; ls >> n;
        p.resize(n);
        for (size_t b = 0; b < n; ++b) { unsigned x; ls >> std::hex >> x >> std::dec; p[b] = (unsigned char)x; }
      }
    }
  }
  CUfunction fn[2];
  Kernel* order[2] = {nullptr, nullptr};
  for (Kernel& k : ks) order[k.name == "heun_predict" ? 0 : 1] = &k;
  for (int s = 0; s < 2; ++s) {
    if (!order[s]) { std::fprintf(stderr, "manifest lacks a kernel\n"); return 1; }
    CK(cuModuleGetFunction(&fn[s], mod, order[s]->name.c_str()));
    for (auto& p : order[s]->params) order[s]->pointers.push_back(p.data());
    std::printf("%s: %zu parameters, %zu work-items in groups of %zu\n", order[s]->name.c_str(), order[s]->params.size(),
                order[s]->global, order[s]->local);
  }
  for (int step = 0; step < steps; ++step)
    for (int s = 0; s < 2; ++s) {
      Kernel& k = *order[s];
      CK(cuLaunchKernel(fn[s], unsigned(k.global / k.local), 1, 1, unsigned(k.local), 1, 1, 0, nullptr, k.pointers.data(), nullptr));
    }
  CK(cuCtxSynchronize());
  for (auto& [id, d] : bufs) {  // a checksum of each buffer's floats, to see that the steps ran finite
    size_t size; CK(cuMemGetAddressRange(nullptr, &size, d));
    std::vector<float> h(size / 4); CK(cuMemcpyDtoH(h.data(), d, h.size() * 4));
    double sum = 0; size_t bad = 0;
    for (float x : h) { if (x == x && x - x == 0) sum += x; else ++bad; }
    std::printf("buffer %d: %zu floats, sum %.9g, %zu not finite\n", id, h.size(), sum, bad);
  }
  return 0;
}
