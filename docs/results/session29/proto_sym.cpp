// Session 29 prototype harness (docs/PERF_NOTES.md, attempt 38; not part of the build): session
// 27's proto_march.cpp with ORDER 9's launch (work-groups of 32 x TY columns: "9:32:TY:TZ:WG",
// WG = 32·TY) and PROTO_NOHELD=1 (every element free, one inverse mass, which ORDER 9 needs to
// match the gather). Session 27's header: from session 26's proto_tile.cpp: main's stage pair (layout 5) on a dense N³ cube, the gather
// (ORDER 0) against the march up columns of TZ cells (ORDER 4, proto_march.cl), each configuration
// checked against the first.
//   g++ -O2 -std=c++20 proto_march.cpp -o proto_march -lOpenCL
//   ./proto_march N STEPS proto_march.cl "ORDER:TX:TY:TZ:WG ..."   (march: "4:0:0:TZ:WG")
#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cctype>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#define CK(x) do { cl_int e_ = (x); if (e_ != CL_SUCCESS) { std::fprintf(stderr, "%s: %d\n", #x, e_); std::exit(1); } } while (0)

static cl_context ctx; static cl_device_id dev; static cl_command_queue q;
static std::string src;

// PROTO_PTX=dir (NVIDIA): each program's binary (PTX) written there, and ptxas's register counts
// (-cl-nv-verbose) printed.
static cl_program build(const std::string& opts0) {
  const char* dump = std::getenv("PROTO_PTX");
  const std::string opts = opts0 + (dump ? " -cl-nv-verbose" : "");
  const char* s = src.c_str(); cl_int err;
  cl_program p = clCreateProgramWithSource(ctx, 1, &s, nullptr, &err); CK(err);
  const cl_int built = clBuildProgram(p, 1, &dev, opts.c_str(), nullptr, nullptr);
  if (dump && built == CL_SUCCESS) {
    size_t n; clGetProgramBuildInfo(p, dev, CL_PROGRAM_BUILD_LOG, 0, nullptr, &n);
    std::string log(n, 0); clGetProgramBuildInfo(p, dev, CL_PROGRAM_BUILD_LOG, n, log.data(), nullptr);
    std::printf("build %s:\n%s\n", opts.c_str(), log.c_str());
    size_t bs; CK(clGetProgramInfo(p, CL_PROGRAM_BINARY_SIZES, sizeof bs, &bs, nullptr));
    std::string bin(bs, 0); char* bp = bin.data();
    CK(clGetProgramInfo(p, CL_PROGRAM_BINARIES, sizeof bp, &bp, nullptr));
    static int built_count = 0;  // numbered: a stage pair's two programs differ early in their options
    std::ofstream(std::string(dump) + "/program" + std::to_string(built_count++) + ".ptx") << bin.c_str();
    std::printf("program%d: %s\n", built_count - 1, opts.c_str());
  }
  if (built != CL_SUCCESS) {
    size_t n; clGetProgramBuildInfo(p, dev, CL_PROGRAM_BUILD_LOG, 0, nullptr, &n);
    std::string log(n, 0); clGetProgramBuildInfo(p, dev, CL_PROGRAM_BUILD_LOG, n, log.data(), nullptr);
    std::fprintf(stderr, "build %s:\n%s\n", opts.c_str(), log.c_str()); std::exit(1);
  }
  return p;
}

static cl_half to_half(float x) {  // IEEE binary16, rounded to nearest (as vstore_half_rte)
  const cl_half sign = std::signbit(x) ? 0x8000 : 0;
  const float a = std::fabs(x);
  if (a < std::ldexp(1.f, -14)) return cl_half(sign | std::lround(std::ldexp(a, 24)));  // subnormal (or 2^-14)
  int ex; std::frexp(a, &ex);  // a = m·2^ex, m in [0.5, 1): a = 1.f·2^(ex−1)
  const long q = std::lround(std::ldexp(a, 11 - ex));  // 11 significant bits, 1024..2048
  return cl_half(sign | ((ex - 1 + 15) << 10) + (q - 1024));  // q = 2048 carries into the exponent
}

// The state (u, v) of n elements packed into a 32 B-per-element arena in the given layout.
static std::vector<float> pack(int layout, const std::vector<float>& u, const std::vector<float>& v, size_t n) {
  std::vector<float> a(8 * n, 0.f);
  for (size_t e = 0; e < n; ++e)
    for (int c = 0; c < 3; ++c) {
      const float uc = u[3 * e + c], vc = v[3 * e + c];
      if (layout == 2) { a[c * n + e] = uc; a[(3 + c) * n + e] = vc; continue; }
      a[4 * e + c] = uc;
      if (layout == 1) (c == 0 ? a[4 * e + 3] : a[4 * n + 2 * e + c - 1]) = vc;
      else if (layout == 0 || layout == 3) a[4 * n + 4 * e + c] = vc;
    }
  if (layout == 4) {  // half4 velocities, 8 B each
    std::vector<cl_half> hv(4 * n, 0);
    for (size_t e = 0; e < n; ++e) for (int c = 0; c < 3; ++c) hv[4 * e + c] = to_half(v[3 * e + c]);
    std::memcpy(a.data() + 4 * n, hv.data(), hv.size() * sizeof(cl_half));
  }
  return a;
}
static float unpack_u(int layout, const std::vector<float>& a, size_t n, size_t e, int c) {
  return layout == 2 ? a[c * n + e] : a[4 * e + c];
}

int main(int argc, char** argv) {
  const int N = argc > 1 ? std::atoi(argv[1]) : 115;
  const int steps = argc > 2 ? std::atoi(argv[2]) : 2000;
  std::ifstream f(argc > 3 ? argv[3] : "proto_layout.cl"); std::stringstream ss; ss << f.rdbuf(); src = ss.str();
  struct Config { int order, tx, ty, tz; size_t wg; };
  std::vector<Config> configs;
  { std::istringstream ls(argc > 4 ? argv[4] : "0:0:0:0:256"); for (std::string t; ls >> t;) {
      Config c{}; std::sscanf(t.c_str(), "%d:%d:%d:%d:%zu", &c.order, &c.tx, &c.ty, &c.tz, &c.wg); configs.push_back(c); } }
  const int layout = 5;
  cl_platform_id plats[8]; cl_uint np; CK(clGetPlatformIDs(8, plats, &np));
  cl_int err = CL_DEVICE_NOT_FOUND;
  for (cl_uint i = 0; i < np && err != CL_SUCCESS; ++i) err = clGetDeviceIDs(plats[i], CL_DEVICE_TYPE_GPU, 1, &dev, nullptr);
  if (err != CL_SUCCESS) CK(clGetDeviceIDs(plats[0], CL_DEVICE_TYPE_ALL, 1, &dev, nullptr));
  char name[256]; clGetDeviceInfo(dev, CL_DEVICE_NAME, 256, name, nullptr);
  ctx = clCreateContext(nullptr, 1, &dev, nullptr, nullptr, &err); CK(err);
  q = clCreateCommandQueue(ctx, dev, CL_QUEUE_PROFILING_ENABLE, &err); CK(err);

  const int G = N + 2, sy = G, sz = G * G; const size_t n = size_t(N) * N * N;
  std::vector<int> grid(size_t(G) * G * G, -1); std::vector<cl_uint> cell(n);
  for (int z = 0; z < N; ++z) for (int y = 0; y < N; ++y) for (int x = 0; x < N; ++x) {
    const size_t e = x + size_t(N) * (y + size_t(N) * z);
    cell[e] = (x + 1) + sy * (y + 1) + sz * (z + 1); grid[cell[e]] = int(e);
  }
  const float h = 2.5e-3f, dt = 1e-5f, zeta = 0.1f;
  const bool noheld = std::getenv("PROTO_NOHELD") && std::atoi(std::getenv("PROTO_NOHELD"));
  std::mt19937 rng(7); std::uniform_real_distribution<float> U(-1, 1);
  std::vector<float> u(3 * n), v(3 * n), W(n), E(n, 1500.f);
  for (size_t e = 0; e < n; ++e) {
    for (int c = 0; c < 3; ++c) { u[3 * e + c] = 1e-4f * U(rng); v[3 * e + c] = 1e-3f * U(rng); }
    W[e] = (e % 97 == 0 && !noheld) ? 0.f : 1.f / (1000 * h * h * h);
  }
  auto mk = [&](size_t bytes, const void* p) { cl_int e2; cl_mem m = clCreateBuffer(ctx, CL_MEM_READ_WRITE | (p ? CL_MEM_COPY_HOST_PTR : 0), bytes, const_cast<void*>(p), &e2); CK(e2); return m; };

  const size_t cn = size_t(1) << 25;  // copy bandwidth: 32M float4 = 512 MB read and written
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
  cl_mem bg = mk(grid.size() * 4, grid.data()), bc = mk(n * 4, cell.data()), bW = mk(n * 4, W.data()), bE = mk(n * 4, E.data());

  std::vector<float> ref;
  for (const Config& c : configs) {
    const size_t wg = c.wg;
    // the element list: identity (ORDER 1) or tiles of TX × TY × TZ (ORDER 2); unused otherwise
    std::vector<cl_uint> list(n);
    if (c.order == 2) {
      size_t k = 0;
      for (int tz = 0; tz < N; tz += c.tz) for (int ty = 0; ty < N; ty += c.ty) for (int tx = 0; tx < N; tx += c.tx)
        for (int z = tz; z < std::min(N, tz + c.tz); ++z) for (int y = ty; y < std::min(N, ty + c.ty); ++y)
          for (int x = tx; x < std::min(N, tx + c.tx); ++x) list[k++] = cl_uint(x + size_t(N) * (y + size_t(N) * z));
    } else {
      for (size_t e = 0; e < n; ++e) list[e] = cl_uint(e);
    }
    cl_mem bM = mk(n * 4, list.data());
    const std::vector<float> init = pack(0, u, v, n);
    cl_mem m[3] = {mk(32 * n, init.data()), mk(32 * n, nullptr), mk(32 * n, nullptr)};  // base, predicted, result
    // Layout 5: the state in layout 0, the predicted stage in layout 1 (one program per stage).
    // PROTO_OPTS replaces the build options (session 25: main's are -cl-std=CL1.2 -cl-mad-enable
    // -cl-denorms-are-zero on GPUs)
    const char* opts_env = std::getenv("PROTO_OPTS");
    const std::string base_opts = opts_env ? std::string(opts_env) + " " : "-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero ";
    const std::string dims = " -DORDER=" + std::to_string(c.order) + " -DNC=" + std::to_string(N) + "u -DTX=" + std::to_string(std::max(1, c.tx)) +
                             "u -DTY=" + std::to_string(std::max(1, c.ty)) + "u -DTZ=" + std::to_string(std::max(1, c.tz)) + "u";
    cl_program p = build(base_opts + "-DLAYOUT=0 -DLOUT=1" + dims);
    // PROTO_REVERSE=1 (attempt 35): the second stage steps the elements in reverse order
    const bool reverse = std::getenv("PROTO_REVERSE") && std::atoi(std::getenv("PROTO_REVERSE"));
    cl_program p2 = build(base_opts + "-DLAYOUT=0 -DLSRC=1" + dims + (reverse ? " -DREVERSE=1" : ""));
    cl_kernel k1 = clCreateKernel(p, "stage", &err); CK(err);
    cl_kernel k2 = clCreateKernel(p2, "stage", &err); CK(err);
    size_t gs = (n + wg - 1) / wg * wg;
    if (c.order == 3) {
      const size_t nt = size_t((N + c.tx - 1) / c.tx) * ((N + c.ty - 1) / c.ty) * ((N + c.tz - 1) / c.tz);
      if (size_t(c.tx) * c.ty * c.tz != wg) { std::fprintf(stderr, "ORDER 3: TX·TY·TZ must be the work-group size\n"); return 1; }
      gs = nt * wg;
    }
    if (c.order >= 4) gs = (size_t(N) * N * ((N + c.tz - 1) / c.tz) + wg - 1) / wg * wg;  // a work-item per column piece
    if (c.order == 9 || c.order == 10) {  // tiles of 30 owned columns along x, TY - 1 rows along y, TZ planes
      if (c.tx != 32 || size_t(32 * c.ty) != wg) { std::fprintf(stderr, "ORDER 9, 10: ORDER:32:TY:TZ:32·TY\n"); return 1; }
      gs = size_t((N + 29) / 30) * ((N + c.ty - 2) / (c.ty - 1)) * ((N + c.tz - 1) / c.tz) * wg;
    }
    if (c.order == 7) gs = (2 * size_t(N) * N * ((N + c.tz - 1) / c.tz) + wg - 1) / wg * wg;  // two per piece
    std::vector<cl_event>* events = nullptr;  // when set, each stage's event is kept (profiling)
    auto stage = [&](cl_mem s, cl_mem b, cl_mem o, int second) {
      cl_kernel k = second ? k2 : k1;
      int i = 0;
      for (cl_mem* a : {&s, &b, &o, &bW, &bE, &bg, &bc, &bM}) CK(clSetKernelArg(k, i++, sizeof(cl_mem), a));
      CK(clSetKernelArg(k, i++, sizeof(int), &sy)); CK(clSetKernelArg(k, i++, sizeof(int), &sz));
      CK(clSetKernelArg(k, i++, sizeof(float), &h)); CK(clSetKernelArg(k, i++, sizeof(float), &dt));
      CK(clSetKernelArg(k, i++, sizeof(float), &zeta)); CK(clSetKernelArg(k, i++, sizeof(int), &second));
      cl_uint nn = cl_uint(n); CK(clSetKernelArg(k, i++, sizeof(cl_uint), &nn));
      cl_event ev;
      CK(clEnqueueNDRangeKernel(q, k, 1, nullptr, &gs, &wg, 0, nullptr, events ? &ev : nullptr));
      if (events) events->push_back(ev);
    };
    int a = 0, b = 2;
    // PROTO_INPLACE=1: the corrected stage written over the step's base (as main's heun_correct)
    // instead of into the other of two state buffers
    const bool inplace = std::getenv("PROTO_INPLACE") && std::atoi(std::getenv("PROTO_INPLACE"));
    auto step = [&] {
      stage(m[a], m[a], m[1], 0);
      stage(m[1], m[a], inplace ? m[a] : m[b], 1);
      if (!inplace) std::swap(a, b);
    };
    for (int s = 0; s < 20; ++s) step();
    std::vector<float> out(8 * n);
    CK(clEnqueueReadBuffer(q, m[a], CL_TRUE, 0, 32 * n, out.data(), 0, nullptr, nullptr));
    std::vector<float> uo(3 * n);
    double diff = 0, scale = 0;
    bool finite = true;
    for (size_t e = 0; e < n; ++e) for (int c = 0; c < 3; ++c) {
      uo[3 * e + c] = unpack_u(layout, out, n, e, c);
      const double d0 = uo[3 * e + c] - u[3 * e + c];
      finite = finite && std::isfinite(d0);
      scale = std::max(scale, std::fabs(d0));
      if (!ref.empty()) diff = std::max(diff, std::fabs(double(uo[3 * e + c]) - ref[3 * e + c]));
    }
    if (ref.empty()) ref = uo;
    double checksum = 0;  // to compare runs of separate processes (the environment's variants)
    for (size_t i = 0; i < uo.size(); ++i) checksum += double(uo[i]) * double(1 + i % 1013);
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
    std::vector<cl_event> evs;
    events = &evs;
    for (int s = 0; s < 200; ++s) step();
    CK(clFinish(q));
    events = nullptr;
    double st[2] = {0, 0};
    for (size_t i = 0; i < evs.size(); ++i) {
      cl_ulong t0, t1;
      CK(clGetEventProfilingInfo(evs[i], CL_PROFILING_COMMAND_START, sizeof t0, &t0, nullptr));
      CK(clGetEventProfilingInfo(evs[i], CL_PROFILING_COMMAND_END, sizeof t1, &t1, nullptr));
      st[i % 2] += (t1 - t0) * 1e-3 / 200;
      clReleaseEvent(evs[i]);
    }
    if (inplace) std::printf("in place  ");
    if (reverse) std::printf("reverse  ");
    std::printf("order %d tile %3d x %2d x %2d wg %3zu  stage1 %6.1f us  stage2 %6.1f us  ", c.order, c.tx, c.ty, c.tz, wg, st[0], st[1]);
    std::printf("layout %d  steps/s %8.0f  us/step %7.1f  %%bw(184B) %5.1f  moved %.3g  diff %.3g  checksum %.17g  %s\n", layout, sps,
                1e6 / sps, 100 * sps * 184.0 * n / bw, scale, diff, checksum, finite ? "finite" : "NONFINITE");
    std::fflush(stdout);
    for (cl_mem x : m) clReleaseMemObject(x);
    clReleaseMemObject(bM);
    clReleaseKernel(k1); clReleaseKernel(k2); clReleaseProgram(p);
    clReleaseProgram(p2);
  }
  return 0;
}
