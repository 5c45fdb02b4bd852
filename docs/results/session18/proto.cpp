// Session 18 prototype harness (docs/PERF_NOTES.md, attempts 21 and 22; not part of the build): times
// stage_gather (main's form) against stage_tile (2.5-D blocking) on a dense N³ cube, two stages
// per Heun step, and checks they agree.
//   g++ -O2 -std=c++20 proto.cpp -o proto -lOpenCL
//   ./proto N STEPS proto.cl [TILE_VARIANTS]   (PROTO_BASE: build options instead of
//   -cl-fast-relaxed-math -cl-mad-enable; PROTO_OPTS: added options; PROTO_DUMP=DIR: program binaries;
//   PROTO_GATHER_VARIANTS=1: also the gather with E in v.w and with constant coefficients;
//   PROTO_UNIFORM_E=1: every E = 1500 Pa, which the constant-coefficient variant assumes)
#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#define CK(x) do { cl_int e_ = (x); if (e_ != CL_SUCCESS) { std::fprintf(stderr, "%s: %d\n", #x, e_); std::exit(1); } } while (0)

static cl_context ctx; static cl_device_id dev; static cl_command_queue q;
static std::string src;

static cl_program build(const std::string& opts) {
  const char* s = src.c_str(); cl_int err;
  cl_program p = clCreateProgramWithSource(ctx, 1, &s, nullptr, &err); CK(err);
  if (clBuildProgram(p, 1, &dev, opts.c_str(), nullptr, nullptr) != CL_SUCCESS) {
    size_t n; clGetProgramBuildInfo(p, dev, CL_PROGRAM_BUILD_LOG, 0, nullptr, &n);
    std::string log(n, 0); clGetProgramBuildInfo(p, dev, CL_PROGRAM_BUILD_LOG, n, log.data(), nullptr);
    std::fprintf(stderr, "build %s:\n%s\n", opts.c_str(), log.c_str()); std::exit(1);
  }
  size_t n; clGetProgramBuildInfo(p, dev, CL_PROGRAM_BUILD_LOG, 0, nullptr, &n);
  std::string log(n, 0); clGetProgramBuildInfo(p, dev, CL_PROGRAM_BUILD_LOG, n, log.data(), nullptr);
  if (getenv("PROTO_LOG")) std::fprintf(stderr, "[%s]\n%s\n", opts.c_str(), log.c_str());
  if (const char* dump = getenv("PROTO_DUMP")) {  // the program binary (PTX on NVIDIA)
    size_t bn; clGetProgramInfo(p, CL_PROGRAM_BINARY_SIZES, sizeof bn, &bn, nullptr);
    std::string bin(bn, 0); unsigned char* bp = reinterpret_cast<unsigned char*>(bin.data());
    clGetProgramInfo(p, CL_PROGRAM_BINARIES, sizeof bp, &bp, nullptr);
    static int count = 0;
    std::ofstream(std::string(dump) + "/prog" + std::to_string(count++) + ".ptx") << "// " << opts << "\n" << bin;
  }
  return p;
}

int main(int argc, char** argv) {
  const int N = argc > 1 ? std::atoi(argv[1]) : 115;
  const int steps = argc > 2 ? std::atoi(argv[2]) : 2000;
  std::ifstream f(argc > 3 ? argv[3] : "proto.cl"); std::stringstream ss; ss << f.rdbuf(); src = ss.str();
  cl_platform_id plats[8]; cl_uint np; CK(clGetPlatformIDs(8, plats, &np));
  cl_int err = CL_DEVICE_NOT_FOUND;
  for (cl_uint i = 0; i < np && err != CL_SUCCESS; ++i) err = clGetDeviceIDs(plats[i], CL_DEVICE_TYPE_GPU, 1, &dev, nullptr);
  if (err != CL_SUCCESS) CK(clGetDeviceIDs(plats[0], CL_DEVICE_TYPE_ALL, 1, &dev, nullptr));
  char name[256]; clGetDeviceInfo(dev, CL_DEVICE_NAME, 256, name, nullptr);
  ctx = clCreateContext(nullptr, 1, &dev, nullptr, nullptr, &err); CK(err);
  q = clCreateCommandQueue(ctx, dev, 0, &err); CK(err);

  const int G = N + 2, sy = G, sz = G * G; const size_t n = size_t(N) * N * N;
  std::vector<int> grid(size_t(G) * G * G, -1); std::vector<cl_uint> cell(n);
  for (int z = 0; z < N; ++z) for (int y = 0; y < N; ++y) for (int x = 0; x < N; ++x) {
    const size_t e = x + size_t(N) * (y + size_t(N) * z);
    cell[e] = (x + 1) + sy * (y + 1) + sz * (z + 1); grid[cell[e]] = int(e);
  }
  const float h = 2.5e-3f, dt = 1e-5f, zeta = 0.1f;
  std::mt19937 rng(7); std::uniform_real_distribution<float> U(-1, 1);
  std::vector<cl_float4> u(n), v(n); std::vector<float> E(n);
  for (size_t e = 0; e < n; ++e) {
    u[e] = {{1e-4f * U(rng), 1e-4f * U(rng), 1e-4f * U(rng), (e % 97 == 0) ? 0.f : 1.f / (1000 * h * h * h)}};
    v[e] = {{1e-3f * U(rng), 1e-3f * U(rng), 1e-3f * U(rng), 0}};
    E[e] = getenv("PROTO_UNIFORM_E") ? 1500.f : 1500 + 500 * U(rng);
    v[e].s[3] = E[e];  // E also in v.w, for the E_IN_VW variant (the other kernels ignore v.w)
  }
  auto mk = [&](size_t bytes, const void* p) { cl_int e2; cl_mem m = clCreateBuffer(ctx, CL_MEM_READ_WRITE | (p ? CL_MEM_COPY_HOST_PTR : 0), bytes, const_cast<void*>(p), &e2); CK(e2); return m; };
  cl_mem bu = mk(n * 16, u.data()), bv = mk(n * 16, v.data()), bup = mk(n * 16, nullptr), bvp = mk(n * 16, nullptr);
  cl_mem bE = mk(n * 4, E.data()), bg = mk(grid.size() * 4, grid.data()), bc = mk(n * 4, cell.data());

  // Copy bandwidth, as voxbreast bench measures it (read + write of a large buffer).
  const size_t cn = size_t(1) << 25;  // 32M float4 = 512 MB
  cl_mem ca = mk(cn * 16, nullptr), cb = mk(cn * 16, nullptr);
  cl_program pc = build("-cl-fast-relaxed-math"); cl_kernel kc = clCreateKernel(pc, "copy4", &err); CK(err);
  CK(clSetKernelArg(kc, 0, sizeof(cl_mem), &ca)); CK(clSetKernelArg(kc, 1, sizeof(cl_mem), &cb));
  double best = 1e9;
  for (int r = 0; r < 20; ++r) {
    CK(clFinish(q)); auto t0 = std::chrono::steady_clock::now();
    CK(clEnqueueNDRangeKernel(q, kc, 1, nullptr, &cn, nullptr, 0, nullptr, nullptr)); CK(clFinish(q));
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  const double bw = 2.0 * cn * 16 / best;
  std::printf("device %s, N %d (%zu elements), copy bandwidth %.0f GB/s\n", name, N, n, bw / 1e9);
  clReleaseMemObject(ca); clReleaseMemObject(cb);

  auto reset = [&] {
    CK(clEnqueueWriteBuffer(q, bu, CL_TRUE, 0, n * 16, u.data(), 0, nullptr, nullptr));
    CK(clEnqueueWriteBuffer(q, bv, CL_TRUE, 0, n * 16, v.data(), 0, nullptr, nullptr));
  };
  std::vector<cl_float4> ref;
  const int check_steps = 20;
  auto run = [&](const char* label, const std::string& opts, bool tile) {
    cl_program p = build(std::string(getenv("PROTO_BASE") ? getenv("PROTO_BASE") : "-cl-fast-relaxed-math -cl-mad-enable") + " " + opts + " " + (getenv("PROTO_OPTS") ? getenv("PROTO_OPTS") : ""));
    cl_kernel k = clCreateKernel(p, tile ? "stage_tile" : "stage_gather", &err); CK(err);
    size_t wg = 128, gs;
    int TX = 32, TY = 4, TZ = 16;
    if (tile) {
      std::sscanf(opts.c_str(), "-DTX=%d -DTY=%d -DTZ=%d", &TX, &TY, &TZ);
      wg = size_t(TX) * TY;
      gs = wg * ((N + TX - 1) / TX) * ((N + TY - 1) / TY) * ((N + TZ - 1) / TZ);
    } else gs = (n + wg - 1) / wg * wg;
    auto stage = [&](cl_mem a, cl_mem b, cl_mem c, cl_mem d, int second) {
      int i = 0;
      CK(clSetKernelArg(k, i++, sizeof(cl_mem), &a)); CK(clSetKernelArg(k, i++, sizeof(cl_mem), &b));
      CK(clSetKernelArg(k, i++, sizeof(cl_mem), &c)); CK(clSetKernelArg(k, i++, sizeof(cl_mem), &d));
      CK(clSetKernelArg(k, i++, sizeof(cl_mem), &bE)); CK(clSetKernelArg(k, i++, sizeof(cl_mem), &bg));
      if (tile) CK(clSetKernelArg(k, i++, sizeof(int), &N)); else CK(clSetKernelArg(k, i++, sizeof(cl_mem), &bc));
      CK(clSetKernelArg(k, i++, sizeof(int), &sy)); CK(clSetKernelArg(k, i++, sizeof(int), &sz));
      CK(clSetKernelArg(k, i++, sizeof(float), &h)); CK(clSetKernelArg(k, i++, sizeof(float), &dt));
      CK(clSetKernelArg(k, i++, sizeof(float), &zeta)); CK(clSetKernelArg(k, i++, sizeof(int), &second));
      if (!tile) { cl_uint nn = cl_uint(n); CK(clSetKernelArg(k, i++, sizeof(cl_uint), &nn)); }
      CK(clEnqueueNDRangeKernel(q, k, 1, nullptr, &gs, &wg, 0, nullptr, nullptr));
    };
    auto step = [&] { stage(bu, bv, bup, bvp, 0); stage(bup, bvp, bu, bv, 1); };
    reset();
    for (int s = 0; s < check_steps; ++s) step();
    std::vector<cl_float4> out(n);
    CK(clEnqueueReadBuffer(q, bu, CL_TRUE, 0, n * 16, out.data(), 0, nullptr, nullptr));
    double diff = 0, scale = 0;
    bool finite = true;
    for (size_t e = 0; e < n; ++e) for (int c = 0; c < 3; ++c) {
      const double d0 = out[e].s[c] - u[e].s[c];
      finite = finite && std::isfinite(d0);
      scale = std::max(scale, std::fabs(d0));
      if (!ref.empty()) diff = std::max(diff, std::fabs(double(out[e].s[c]) - ref[e].s[c]));
    }
    if (ref.empty()) ref = out;
    for (int s = 0; s < 50; ++s) step();
    CK(clFinish(q));
    double bestt = 1e9;
    for (int round = 0; round < 3; ++round) {
      auto t0 = std::chrono::steady_clock::now();
      for (int s = 0; s < steps; ++s) { step(); if (s % 32 == 31) CK(clFinish(q)); }
      CK(clFinish(q));
      bestt = std::min(bestt, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    const double sps = steps / bestt;
    std::printf("%-10s %-28s steps/s %8.0f  us/step %7.1f  %%bw(184B) %5.1f  moved %.3g  diff %.3g  %s\n", label,
                opts.c_str(), sps, 1e6 / sps, 100 * sps * 184.0 * n / bw, scale, diff, finite ? "finite" : "NONFINITE");
    std::fflush(stdout);
    clReleaseKernel(k); clReleaseProgram(p);
  };
  run("gather", "", false);
  if (getenv("PROTO_GATHER_VARIANTS")) {
    run("gather_ew", "-DE_IN_VW=1", false);
    run("gather_uni", "-DUNIFORM=1 -DUNIFORM_W=64000.0f", false);
  }
  const char* all[] = {"-DTX=32 -DTY=4 -DTZ=16", "-DTX=32 -DTY=4 -DTZ=8", "-DTX=32 -DTY=4 -DTZ=32",
                       "-DTX=32 -DTY=8 -DTZ=16", "-DTX=32 -DTY=8 -DTZ=32", "-DTX=16 -DTY=8 -DTZ=16",
                       "-DTX=64 -DTY=2 -DTZ=16", "-DTX=32 -DTY=4 -DTZ=4", "-DTX=16 -DTY=8 -DTZ=8"};
  const int nv = argc > 4 ? std::atoi(argv[4]) : 7;  // how many tile variants
  for (int i = 0; i < nv && i < 9; ++i) run("tile", all[i < 2 ? 1 - i : i], true);
  run("gather", "", false);
  return 0;
}
