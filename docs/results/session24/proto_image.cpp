// Session 24 prototype harness (docs/PERF_NOTES.md, attempt 28; not part of the build): times a
// Heun step of linear springs on a dense N³ cube with its state in buffers (main's gather, and a
// 3-D range) against the same step with the state in 3-D and 2-D images (the texture path), and
// checks every form against the gather after 20 steps.
//   g++ -O2 -std=c++20 proto_image.cpp -o proto_image -lOpenCL
//   ./proto_image N STEPS proto_image.cl     (PROTO_SHAPES="32x4x1 8x8x2 ...": the 3-D work-group shapes)
#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
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
  return p;
}

enum Kind { GATHER, BUF3D, IMG3D, IMG2D };

int main(int argc, char** argv) {
  const int N = argc > 1 ? std::atoi(argv[1]) : 115;
  const int steps = argc > 2 ? std::atoi(argv[2]) : 2000;
  std::ifstream f(argc > 3 ? argv[3] : "proto_image.cl"); std::stringstream ss; ss << f.rdbuf(); src = ss.str();
  cl_platform_id plats[8]; cl_uint np; CK(clGetPlatformIDs(8, plats, &np));
  cl_int err = CL_DEVICE_NOT_FOUND;
  for (cl_uint i = 0; i < np && err != CL_SUCCESS; ++i) err = clGetDeviceIDs(plats[i], CL_DEVICE_TYPE_GPU, 1, &dev, nullptr);
  if (err != CL_SUCCESS) CK(clGetDeviceIDs(plats[0], CL_DEVICE_TYPE_ALL, 1, &dev, nullptr));
  char name[256]; clGetDeviceInfo(dev, CL_DEVICE_NAME, 256, name, nullptr);
  size_t extn; clGetDeviceInfo(dev, CL_DEVICE_EXTENSIONS, 0, nullptr, &extn);
  std::string ext(extn, 0); clGetDeviceInfo(dev, CL_DEVICE_EXTENSIONS, extn, ext.data(), nullptr);
  const bool writes3d = ext.find("cl_khr_3d_image_writes") != std::string::npos;
  size_t max2d_h = 0; clGetDeviceInfo(dev, CL_DEVICE_IMAGE2D_MAX_HEIGHT, sizeof max2d_h, &max2d_h, nullptr);
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
  std::vector<cl_float4> u(n), v(n);
  for (size_t e = 0; e < n; ++e) {
    u[e] = {{1e-4f * U(rng), 1e-4f * U(rng), 1e-4f * U(rng), (e % 97 == 0) ? 0.f : 1.f / (1000 * h * h * h)}};
    v[e] = {{1e-3f * U(rng), 1e-3f * U(rng), 1e-3f * U(rng), 1500 + 500 * U(rng)}};  // v.w = E
  }
  auto mk = [&](size_t bytes, const void* p) { cl_int e2; cl_mem m = clCreateBuffer(ctx, CL_MEM_READ_WRITE | (p ? CL_MEM_COPY_HOST_PTR : 0), bytes, const_cast<void*>(p), &e2); CK(e2); return m; };

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
  std::printf("device %s, N %d (%zu elements), copy bandwidth %.0f GB/s, 3-D image writes %s, 2-D image height max %zu\n",
              name, N, n, bw / 1e9, writes3d ? "yes" : "no", max2d_h);
  clReleaseMemObject(ca); clReleaseMemObject(cb);
  cl_mem bg = mk(grid.size() * 4, grid.data()), bc = mk(n * 4, cell.data());

  std::vector<cl_float4> ref;
  auto run = [&](Kind kind, const char* label, size_t lx, size_t ly, size_t lz) {
    const bool img = kind == IMG3D || kind == IMG2D;
    if (kind == IMG3D && !writes3d) { std::printf("%-8s skipped: no cl_khr_3d_image_writes\n", label); return; }
    if (kind == IMG2D && max2d_h < n / N) { std::printf("%-8s skipped: N² rows > 2-D image height\n", label); return; }
    // Three state pairs: the step's base (A), its predicted stage (P) and its result (B).
    cl_mem m[6];
    cl_image_format fmt{CL_RGBA, CL_FLOAT};
    for (int i = 0; i < 6; ++i) {
      const void* init = i == 0 ? u.data() : i == 1 ? v.data() : nullptr;
      if (!img) { m[i] = mk(n * 16, init); continue; }
      cl_image_desc d{};
      d.image_type = kind == IMG3D ? CL_MEM_OBJECT_IMAGE3D : CL_MEM_OBJECT_IMAGE2D;
      d.image_width = N; d.image_height = kind == IMG3D ? N : n / N; d.image_depth = kind == IMG3D ? N : 1;
      m[i] = clCreateImage(ctx, CL_MEM_READ_WRITE | (init ? CL_MEM_COPY_HOST_PTR : 0), &fmt, &d, const_cast<void*>(init), &err);
      CK(err);
    }
    cl_program p = build(std::string("-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero") + (writes3d ? " -DIMG3D_WRITES" : ""));
    const char* kname = kind == GATHER ? "stage_gather" : kind == BUF3D ? "stage_buf3d" : kind == IMG3D ? "stage_img3d" : "stage_img2d";
    cl_kernel k = clCreateKernel(p, kname, &err); CK(err);
    const size_t gwg = 128, g1 = (n + gwg - 1) / gwg * gwg;
    const size_t lsz[3] = {lx, ly, lz};
    const size_t gsz[3] = {(N + lx - 1) / lx * lx, (N + ly - 1) / ly * ly, (N + lz - 1) / lz * lz};
    auto stage = [&](cl_mem us, cl_mem vs, cl_mem ub, cl_mem vb, cl_mem uo, cl_mem vo, int second) {
      int i = 0;
      for (cl_mem* a : {&us, &vs, &ub, &vb, &uo, &vo}) CK(clSetKernelArg(k, i++, sizeof(cl_mem), a));
      if (kind == GATHER) {
        CK(clSetKernelArg(k, i++, sizeof(cl_mem), &bg)); CK(clSetKernelArg(k, i++, sizeof(cl_mem), &bc));
        CK(clSetKernelArg(k, i++, sizeof(int), &sy)); CK(clSetKernelArg(k, i++, sizeof(int), &sz));
      }
      CK(clSetKernelArg(k, i++, sizeof(float), &h)); CK(clSetKernelArg(k, i++, sizeof(float), &dt));
      CK(clSetKernelArg(k, i++, sizeof(float), &zeta)); CK(clSetKernelArg(k, i++, sizeof(int), &second));
      if (kind == GATHER) { cl_uint nn = cl_uint(n); CK(clSetKernelArg(k, i++, sizeof(cl_uint), &nn)); }
      else CK(clSetKernelArg(k, i++, sizeof(int), &N));
      if (kind == GATHER) CK(clEnqueueNDRangeKernel(q, k, 1, nullptr, &g1, &gwg, 0, nullptr, nullptr));
      else CK(clEnqueueNDRangeKernel(q, k, 3, nullptr, gsz, lsz, 0, nullptr, nullptr));
    };
    int a = 0, b = 4;  // base pair m[a], m[a+1]; result pair m[b], m[b+1]; predicted m[2], m[3]
    auto step = [&] {
      stage(m[a], m[a + 1], m[a], m[a + 1], m[2], m[3], 0);
      stage(m[2], m[3], m[a], m[a + 1], m[b], m[b + 1], 1);
      std::swap(a, b);
    };
    for (int s = 0; s < 20; ++s) step();
    std::vector<cl_float4> out(n);
    if (img) {
      const size_t origin[3] = {0, 0, 0};
      const size_t region[3] = {size_t(N), kind == IMG3D ? size_t(N) : n / N, kind == IMG3D ? size_t(N) : 1};
      CK(clEnqueueReadImage(q, m[a], CL_TRUE, origin, region, 0, 0, out.data(), 0, nullptr, nullptr));
    } else CK(clEnqueueReadBuffer(q, m[a], CL_TRUE, 0, n * 16, out.data(), 0, nullptr, nullptr));
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
    char shape[32]; std::snprintf(shape, sizeof shape, kind == GATHER ? "128" : "%zux%zux%zu", lx, ly, lz);
    std::printf("%-8s %-9s steps/s %8.0f  us/step %7.1f  %%bw(184B) %5.1f  moved %.3g  diff %.3g  %s\n", label, shape,
                sps, 1e6 / sps, 100 * sps * 184.0 * n / bw, scale, diff, finite ? "finite" : "NONFINITE");
    std::fflush(stdout);
    for (cl_mem x : m) clReleaseMemObject(x);
    clReleaseKernel(k); clReleaseProgram(p);
  };
  std::vector<std::array<size_t, 3>> shapes;
  std::istringstream sh(getenv("PROTO_SHAPES") ? getenv("PROTO_SHAPES") : "32x4x1 32x2x2 16x4x2 8x8x2 8x4x4 4x4x8 64x2x1");
  for (std::string t; sh >> t;) { std::array<size_t, 3> s{}; std::sscanf(t.c_str(), "%zux%zux%zu", &s[0], &s[1], &s[2]); shapes.push_back(s); }
  run(GATHER, "gather", 128, 1, 1);
  for (auto& s : shapes) run(BUF3D, "buf3d", s[0], s[1], s[2]);
  for (auto& s : shapes) run(IMG3D, "img3d", s[0], s[1], s[2]);
  for (auto& s : shapes) run(IMG2D, "img2d", s[0], s[1], s[2]);
  run(GATHER, "gather", 128, 1, 1);
  return 0;
}
