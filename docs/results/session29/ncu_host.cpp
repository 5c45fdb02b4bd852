// Session 29 copy: NCU_NOHELD=1 (every element free) and NCU_BLOCKS (ORDER 9 and 10 launches).
// Session 27 (docs/PERF_NOTES.md, "Session 27"): runs the prototype's stage pair from the PTX that
// NVIDIA's OpenCL compiler produced (proto_march PROTO_PTX dumps) through the CUDA driver API, so
// that Nsight Compute, which does not see OpenCL launches, can profile the very same code. A
// diagnostic only: the product stays OpenCL (no CUDA in the build).
//   g++ -O2 -I/usr/local/cuda/include ncu_host.cpp -o ncu_host -L/usr/local/cuda/lib64/stubs -lcuda
//   ncu --set full ./ncu_host stage1.ptx stage2.ptx N STEPS WG      (NCU_INPLACE=1: corrector in place)
#include <cuda.h>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#define CK(x) do { CUresult r_ = (x); if (r_ != CUDA_SUCCESS) { const char* m_; cuGetErrorString(r_, &m_); std::fprintf(stderr, "%s: %s\n", #x, m_); std::exit(1); } } while (0)

// OpenCL's PTX reads the global offset from %envreg3, which a CUDA launch does not set: zero it.
static std::string load_ptx(const char* path) {
  std::ifstream f(path); std::stringstream ss; ss << f.rdbuf();
  // and drop OpenCL's texture mode, which the driver's JIT may refuse
  return std::regex_replace(std::regex_replace(ss.str(), std::regex("%envreg3"), "0"), std::regex(", texmode_independent"), "");
}

int main(int argc, char** argv) {
  if (argc < 6) { std::fprintf(stderr, "usage: ncu_host stage1.ptx stage2.ptx N STEPS WG\n"); return 2; }
  const int N = std::atoi(argv[3]), steps = std::atoi(argv[4]);
  const unsigned wg = unsigned(std::atoi(argv[5]));
  CK(cuInit(0)); CUdevice dev; CK(cuDeviceGet(&dev, 0)); CUcontext ctx; CK(cuCtxCreate(&ctx, nullptr, 0, dev));
  CUfunction k[2];
  for (int s = 0; s < 2; ++s) {
    const std::string ptx = load_ptx(argv[1 + s]);
    char log[8192] = {0};
    CUjit_option opt[] = {CU_JIT_ERROR_LOG_BUFFER, CU_JIT_ERROR_LOG_BUFFER_SIZE_BYTES};
    void* val[] = {log, (void*)(size_t)sizeof log};
    CUmodule m;
    const CUresult r = cuModuleLoadDataEx(&m, ptx.c_str(), 2, opt, val);
    if (r != CUDA_SUCCESS) std::fprintf(stderr, "%s: JIT log: %s\n", argv[1 + s], log);
    CK(r);
    CK(cuModuleGetFunction(&k[s], m, "stage"));
  }
  // the harness's cube (proto_march.cpp): padded grid, state in layout 0, every 97th element held
  const int G = N + 2, sy = G, sz = G * G; const size_t n = size_t(N) * N * N;
  std::vector<int> grid(size_t(G) * G * G, -1); std::vector<unsigned> cell(n);
  for (int z = 0; z < N; ++z) for (int y = 0; y < N; ++y) for (int x = 0; x < N; ++x) {
    const size_t e = x + size_t(N) * (y + size_t(N) * z);
    cell[e] = (x + 1) + sy * (y + 1) + sz * (z + 1); grid[cell[e]] = int(e);
  }
  float h = 2.5e-3f, dt = 1e-5f, zeta = 0.1f;
  const bool noheld = std::getenv("NCU_NOHELD") && std::atoi(std::getenv("NCU_NOHELD"));
  std::mt19937 rng(7); std::uniform_real_distribution<float> U(-1, 1);
  std::vector<float> st(8 * n, 0.f), W(n), E(n, 1500.f);
  for (size_t e = 0; e < n; ++e) {
    for (int c = 0; c < 3; ++c) { st[4 * e + c] = 1e-4f * U(rng); st[4 * n + 4 * e + c] = 1e-3f * U(rng); }
    W[e] = (e % 97 == 0 && !noheld) ? 0.f : 1.f / (1000 * h * h * h);
  }
  auto mk = [](size_t bytes, const void* p) { CUdeviceptr d; CK(cuMemAlloc(&d, bytes)); if (p) CK(cuMemcpyHtoD(d, p, bytes)); return d; };
  CUdeviceptr a = mk(32 * n, st.data()), pred = mk(32 * n, nullptr), b = mk(32 * n, nullptr);
  CUdeviceptr dW = mk(4 * n, W.data()), dE = mk(4 * n, E.data()), dg = mk(4 * grid.size(), grid.data()),
              dc = mk(4 * n, cell.data()), dL = mk(4 * n, cell.data());
  unsigned nn = unsigned(n);
  const bool inplace = std::getenv("NCU_INPLACE") && std::atoi(std::getenv("NCU_INPLACE"));
  // NCU_BLOCKS: the launch's work-groups where they are not one work-item per element (ORDERs 9, 10)
  const unsigned blocks = std::getenv("NCU_BLOCKS") ? unsigned(std::atoi(std::getenv("NCU_BLOCKS"))) : unsigned((n + wg - 1) / wg);
  for (int s = 0; s < steps; ++s)
    for (int stage = 0; stage < 2; ++stage) {
      // NCU_INPLACE=1: the corrector writes over the step's base, as main's heun_correct does
      CUdeviceptr src = stage ? pred : a, base = a, out = stage ? (inplace ? a : b) : pred;
      int second = stage;
      void* args[] = {&src, &base, &out, &dW, &dE, &dg, &dc, &dL, (void*)&sy, (void*)&sz, &h, &dt, &zeta, &second, &nn};
      CK(cuLaunchKernel(k[stage], blocks, 1, 1, wg, 1, 1, 0, nullptr, args, nullptr));
      if (stage && !inplace) std::swap(a, b);
    }
  CK(cuCtxSynchronize());
  std::vector<float> out(4 * n);
  CK(cuMemcpyDtoH(out.data(), a, 16 * n));
  double cs = 0; for (size_t i = 0; i < n; ++i) for (int c = 0; c < 3; ++c) cs += out[4 * i + c];
  std::printf("ncu_host: %d steps of %zu elements, sum of u %.9g\n", steps, n, cs);
  return 0;
}
