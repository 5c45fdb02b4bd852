#include "apps/bench_throughput.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <vector>

#include "engine/bench/bench_knobs.hpp"
#include "engine/bench/bench_scenes.hpp"
#include "engine/bench/gather_floor.hpp"
#include "engine/bench/paced_timing.hpp"
#include "engine/lattice/lattice.hpp"
#include "engine/lattice/voxelise.hpp"
#include "engine/sim/simulator.hpp"

namespace vb::app {
namespace {

struct BenchCase {
  std::string name;
  int edge = 0;                     ///< the cube's edge (elements), for cube models
  std::string integrator = "heun";  ///< a bench knob name (engine/bench/bench_knobs.hpp)
  Precision precision = Precision::Float;
  std::string law = "linear";
  bool volume = false;
  const bench::BenchScene* phantom = nullptr;  ///< the phantom's scene; none: the cube
};

/// The bundled phantom's spacing for a ~36k-element breast (34,961 elements at 3.2 mm; 18,413 at
/// its own 4 mm): the size of the main paper's hyperelastic breast model and of the 36k target (docs/BENCHMARKS.md).
constexpr double kBreastSpacing = 0.0032;

/// A cube of `edge`³ adipose elements, base held, under gravity: the standard linear block, its
/// connection dashpots of ratio `dashpot_ratio` (the solver's default 0.1 unless asked).
Scene block_scene(const BenchCase& c, double dashpot_ratio) {
  Scene s;
  const double h = 0.002;
  ShapeSpec box;
  box.kind = ShapeSpec::Kind::Box;
  box.min_m = Vec3::Zero();
  box.max_m = Vec3::Constant(c.edge * h);
  box.label = "adipose";
  s.model.spacing_m = h;
  s.model.shapes.push_back(box);
  MaterialSpec m;
  m.name = "adipose";
  m.youngs_modulus_pa = 3000;
  m.law = c.law;
  if (c.law == "ogden") {  // a two-term Ogden tissue with μ₀ = 1.8 kPa
    m.ogden_mu_pa = {1200, -300};
    m.ogden_alpha = {4, -2};
  }
  if (c.law == "biphasic") {  // the validation's biphasic springs (docs/VALIDATION.md)
    m.cubic = 20;
    m.critical_strain = 0.1;
  }
  m.poisson_ratio = 0.45;
  s.materials["adipose"] = m;
  bench::apply_integrator(s, c.integrator);
  s.solver.precision = c.precision;
  s.solver.damping_per_s = 5;
  s.solver.dashpot_ratio = dashpot_ratio;
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -9.80665);
  AnchorSpec base;
  base.name = "base";
  base.kind = AnchorSpec::Kind::HalfSpace;
  base.point_m = Vec3(0, 0, h);
  base.normal = Vec3(0, 0, -1);
  s.anchors.push_back(base);
  s.volume.preserve = c.volume;
  return s;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Steps per second, timed over enough steps to last about `target_s`.
double time_steps(Simulator& sim, double target_s) {
  sim.advance(3);
  sim.check();  // warm-up, includes any lazy compilation
  return bench::paced_steps_per_s(sim.context().queue, [&](std::int64_t steps) { sim.advance(steps); }, target_s);
}

/// The gather floor's rate for a model whose step is the one the floor mirrors: Heun in float on
/// the GPUs' plain path (the predicted stage packed: linear springs, one work-item per element, no
/// list, constraint or contact). None for any other step, and where the floor's own arrays would
/// not fit on the device beside the model's (said on the terminal).
std::optional<double> gather_floor_rate(const ClContext& cl, const Simulator& sim, const Scene& scene,
                                        const Lattice& lattice, const ElementArrays& el, double target_s) {
  if (!sim.pred_packed() || sim.precision() != Precision::Float) return std::nullopt;
  const double needed = double(sim.device_bytes() + bench::GatherFloor::device_bytes(lattice));
  if (needed > 0.9 * double(cl.info.global_memory_bytes)) {
    std::printf("    gather floor not measured: with the model it needs %.0f MiB of the device's %.0f MiB\n",
                needed / 1048576.0, double(cl.info.global_memory_bytes) / 1048576.0);
    return std::nullopt;
  }
  bench::GatherFloor floor(cl, lattice, el.inverse_mass, sim.step_work_group(), sim.correct_reverse(),
                           std::max<std::size_t>(1, cl.info.simd_width), scene.solver.dashpot_ratio > 0);
  return floor.steps_per_s(target_s);
}

/// Host time to enqueue one step (s), from a batch short enough not to fill the queue (a full queue
/// blocks the host until the device frees room, which would hide a device-bound step). If it is
/// close to the timed step, the host's launches, not the device, set the pace.
double host_enqueue_per_step(Simulator& sim) {
  const std::int64_t steps = 16;
  sim.context().queue.finish();
  const auto t0 = std::chrono::steady_clock::now();
  sim.advance(steps);
  const double enqueue_s = seconds_since(t0);
  sim.context().queue.finish();
  return enqueue_s / double(steps);
}

/// Achievable device bandwidth (bytes/s): read + write of a large buffer.
double copy_bandwidth(const ClContext& cl, std::size_t bytes) {
  cl::Program p = build_program(cl, {"common.cl", "bandwidth.cl"}, "", "-DVB_DOUBLE=0");
  cl::Kernel k(p, "copy_bandwidth");
  const std::size_t n = bytes / 16;
  cl::Buffer a(cl.context, CL_MEM_READ_WRITE, n * 16), b(cl.context, CL_MEM_READ_WRITE, n * 16);
  cl.queue.enqueueFillBuffer(a, cl_float(1), 0, n * 16);
  k.setArg(0, a); k.setArg(1, b); k.setArg(2, cl_uint(n));
  const cl::NDRange global((n + 255) / 256 * 256);
  cl.queue.enqueueNDRangeKernel(k, cl::NullRange, global);
  cl.queue.finish();
  const int reps = 10;
  const auto t0 = std::chrono::steady_clock::now();
  for (int r = 0; r < reps; ++r) cl.queue.enqueueNDRangeKernel(k, cl::NullRange, global);
  cl.queue.finish();
  return 2.0 * double(n * 16) * reps / seconds_since(t0);
}

/// The cost of a launch that does nothing (the copy kernel over 0 elements, one work-group): host
/// time per enqueue in a 16-launch batch (short enough not to block on a full queue) and the
/// device's throughput over 2,000 launches. A step of L launches cannot be faster than L times
/// the larger of the two, however fast its kernels are.
void print_launch_floor(const ClContext& cl) {
  cl::Program p = build_program(cl, {"common.cl", "bandwidth.cl"}, "", "-DVB_DOUBLE=0");
  cl::Kernel k(p, "copy_bandwidth");
  cl::Buffer a(cl.context, CL_MEM_READ_WRITE, 16);
  k.setArg(0, a); k.setArg(1, a); k.setArg(2, cl_uint(0));
  const auto launches = [&](int count) {
    for (int r = 0; r < count; ++r) cl.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(256), cl::NDRange(256));
  };
  launches(100);
  cl.queue.finish();
  auto t0 = std::chrono::steady_clock::now();
  launches(16);
  const double host_s = seconds_since(t0) / 16;
  cl.queue.finish();
  const int many = 2000;
  t0 = std::chrono::steady_clock::now();
  launches(many);
  cl.queue.finish();
  std::printf("launch floor: empty kernel %.2f us/launch host enqueue (16-launch batch), %.2f us/launch over %d launches\n",
              1e6 * host_s, 1e6 * seconds_since(t0) / many, many);
}

/// Bytes a Heun step must move per element, counting each element's own state once per stage
/// (neighbour reads are served from cache): stage 1 reads u, v, E, cell, grid and writes ũ, ṽ;
/// stage 2 reads u, v, ũ, ṽ, E, cell, grid and writes u, v. Hyperelastic tissues add, per
/// stage, the stress pass (reads u, cell, grid, tissue; writes Q and C: 4 vectors) and the
/// gather's read of the element's own Q and C and tissue. Biphasic springs add the element's own
/// tissue id per stage (the neighbours' ids and material rows are neighbour reads). With the
/// predicted stage packed (Simulator::pred_packed) ũ, ṽ are 6 reals, written once and read once.
double heun_bytes_per_element(std::size_t real_size, const std::string& law, bool pred_packed) {
  const double vec = 4.0 * double(real_size), scalar = double(real_size), idx = 4.0;
  const double stage = pred_packed ? 6 * scalar : 2 * vec;  // ũ, ṽ
  const double springs = (2 * vec + scalar + 2 * idx + stage) + (2 * vec + stage + scalar + 2 * idx + 2 * vec);
  const double stress_pass = (vec + 2 * idx + 1 + 4 * vec) + (4 * vec + 1);
  if (law == "linear") return springs;
  if (law == "biphasic") return springs + 2 * 1.0;
  return springs + 2 * stress_pass;
}

/// Device time per step with the host ahead of the device (s; none if it could not be told
/// apart), and whether the host stayed ahead.
struct DeviceAlone {
  std::optional<double> seconds_per_step;
  bool host_ahead = false;
};

/// The device's own time per step: a kernel holds the queue while the host enqueues `steps` steps
/// (about `host_s_per_step` each) behind it, so the time to the end of the queue less the holding
/// kernel's own time is the steps' device time, however slow the host's launches are. (A profiling
/// queue cannot tell: on NVIDIA its events slow the device as well, and its completion callbacks
/// came late, often after the queue had drained, so the holder's end cannot be seen directly.)
/// The holder's time is measured beside each of three runs and the median run taken, because on a
/// loaded CPU device (PoCL beside other work) the holder's time varies from run to run. If the host had not
/// finished enqueueing when the holding kernel ended, the time includes waits for the host and is
/// only an upper bound.
DeviceAlone device_time_per_step(const ClContext& cl, Simulator& sim, std::int64_t steps, double host_s_per_step) {
  cl::Program p = build_program(cl, {"common.cl", "bandwidth.cl"}, "", "-DVB_DOUBLE=0");
  cl::Kernel hold(p, "hold_queue");
  cl::Buffer scratch(cl.context, CL_MEM_READ_WRITE, 128 * sizeof(float));
  cl.queue.enqueueFillBuffer(scratch, cl_float(0), 0, 128 * sizeof(float));
  hold.setArg(0, scratch);
  const cl::NDRange group(128);
  const auto hold_alone = [&] {
    cl.queue.finish();
    const auto t0 = std::chrono::steady_clock::now();
    cl.queue.enqueueNDRangeKernel(hold, cl::NullRange, group, group);
    cl.queue.finish();
    return seconds_since(t0);
  };
  const cl_uint probe = 1u << 16;
  hold.setArg(1, probe);
  hold_alone();  // the first launch may compile
  const double per_iteration = hold_alone() / double(probe);
  // three times the host's enqueue time of the batch, and at least 2 ms
  const double wanted_s = 3 * host_s_per_step * double(steps) + 0.002;
  hold.setArg(1, cl_uint(std::min(4.0e9, wanted_s / std::max(per_iteration, 1e-12))));
  std::vector<DeviceAlone> runs;
  for (int run = 0; run < 3; ++run) {
    const double held_s = 0.5 * (hold_alone() + hold_alone());
    cl.queue.finish();
    const auto t0 = std::chrono::steady_clock::now();
    cl.queue.enqueueNDRangeKernel(hold, cl::NullRange, group, group);
    sim.advance(steps);
    const double enqueued_s = seconds_since(t0);
    cl.queue.finish();
    runs.push_back({(seconds_since(t0) - held_s) / double(steps), enqueued_s < held_s});
  }
  std::sort(runs.begin(), runs.end(), [](const DeviceAlone& a, const DeviceAlone& b) { return *a.seconds_per_step < *b.seconds_per_step; });
  // a holder that ran faster than it was timed alone leaves nothing to tell the steps' time by
  if (*runs[1].seconds_per_step <= 0) return {};
  return runs[1];
}

/// Device time per kernel over about 0.2 s of steps of the same model on a profiling queue. On
/// NVIDIA the profiling events make the host the bottleneck, so the profiled step is slower than
/// the timed one; the per-kernel times remain device times.
void print_kernel_profile(const ClContext& cl, const Scene& scene, const Lattice& lattice, const ElementArrays& el,
                          double steps_per_s, const PlanOverrides& plan) {
  const ClContext profiling(cl.info, true);
  Simulator sim(scene, lattice, el, profiling, plan);
  sim.advance(3);
  sim.check();
  const std::int64_t steps = std::max<std::int64_t>(20, std::int64_t(0.2 * steps_per_s));
  const auto t0 = std::chrono::steady_clock::now();
  sim.advance(steps);
  const double enqueue_s = seconds_since(t0);
  profiling.queue.finish();
  const double wall_s = seconds_since(t0);
  double total = 0, launches = 0;
  for (const auto& [name, p] : sim.kernel_profile()) {
    total += p.seconds;
    launches += double(p.launches);
    std::printf("    %-16s %5.2f launches/step %9.2f us/launch %9.2f us/step\n", name.c_str(),
                double(p.launches) / double(steps), 1e6 * p.seconds / double(p.launches), 1e6 * p.seconds / double(steps));
  }
  std::printf("    %.2f launches/step, kernels %.2f us/step of %.2f us/step timed (the rest: gaps between launches); "
              "profiled run %.2f us/step, host enqueue %.2f us/step\n",
              launches / double(steps), 1e6 * total / double(steps), 1e6 / steps_per_s, 1e6 * wall_s / double(steps),
              1e6 * enqueue_s / double(steps));
  std::fflush(stdout);
}

}  // namespace

ThroughputResult run_throughput(const ClContext& cl, const ThroughputOptions& o) {
  ThroughputResult result;
  const std::vector<int>& sizes = o.sizes;
  const double target_s = o.quick ? 0.5 : 2.0;
  const double bandwidth = copy_bandwidth(cl, std::min<std::size_t>(cl.info.max_allocation_bytes / 2, o.quick ? 64u << 20 : 512u << 20));
  result.copy_bandwidth_gb_s = bandwidth / 1e9;
  std::printf("copy bandwidth: %.1f GB/s\n", bandwidth / 1e9);
  if (o.profile) print_launch_floor(cl);

  std::vector<BenchCase> cases;
  // the phantom's scenes as it runs them (each case applies its law and integrator to a copy);
  // every scene is made before the cases point at them
  std::optional<bench::BenchScene> breast, breast_large;
  std::vector<bench::BenchScene> resampled;  // --breast-elements, in the order given
  if (o.breast) breast = bench::image_scene("breast", o.phantom_scene, kBreastSpacing);
  if (o.breast_large) breast_large = bench::image_scene("breast_large", o.phantom_scene, bench::kLargePhantomSpacing);
  if (!o.breast_elements.empty()) {
    // the spacing that gives about N elements: the phantom's own spacing × (own count / N)^(1/3)
    const bench::BenchScene own = bench::image_scene("breast_resampled", o.phantom_scene, 0);
    const double own_count = double(build_lattice(own.volume).element_count());
    for (long target : o.breast_elements) {
      const double spacing = own.scene.model.spacing_m * std::cbrt(own_count / double(target));
      resampled.push_back(bench::image_scene("breast_resampled", o.phantom_scene, spacing));
    }
  }
  if (breast)
    for (const std::string& law : o.laws) {
      cases.push_back({"breast", 0, "heun", Precision::Float, law, false, &*breast});
      if (o.volume) cases.push_back({"breast_volume", 0, "heun", Precision::Float, law, true, &*breast});
    }
  if (breast_large) cases.push_back({"breast_large", 0, "heun", Precision::Float, "linear", false, &*breast_large});
  for (const bench::BenchScene& phantom : resampled)
    for (const std::string& law : o.laws)
      for (const std::string& integrator : o.breast_integrators)
        cases.push_back({"breast_resampled", 0, integrator, Precision::Float, law, false, &phantom});
  for (int edge : sizes) {
    cases.push_back({"block", edge, "heun", Precision::Float});
    if (!o.quick) {
      cases.push_back({"block", edge, "symplectic_euler", Precision::Float});
      if (cl.info.fp64) cases.push_back({"block", edge, "heun", Precision::Double});
    }
    for (const std::string& law : o.laws)
      if (law != "linear") cases.push_back({"block", edge, "heun", Precision::Float, law});
    if (o.volume)
      for (const std::string& law : o.laws)
        cases.push_back({"block_volume", edge, "heun", Precision::Float, law, true});
  }
  nlohmann::json rows = nlohmann::json::array();
  std::ostringstream csv;
  csv << "model,elements,law,integrator,precision,steps_per_s,ns_per_element_step,bytes_per_element_step,"
         "effective_bandwidth_gb_s,fraction_of_copy_bandwidth,device_bytes_per_element,free_elements,"
         "gather_floor_steps_per_s,fraction_of_gather_floor,dashpot_ratio\n";
  for (const BenchCase& c : cases) {
    Scene scene;
    Lattice lattice;
    if (c.phantom) {  // the breast: its tissues (muscle rigid) on the case's law and integrator, float
      scene = c.phantom->scene;
      bench::apply_law(scene, c.law);
      bench::apply_integrator(scene, c.integrator);
      scene.solver.precision = c.precision;
      scene.volume.preserve = c.volume;
      lattice = build_lattice(c.phantom->volume);
    } else {
      scene = block_scene(c, o.cube_dashpot_ratio);
      lattice = build_lattice(voxelise_shapes(scene));
    }
    scene.volume.predictor = o.volume_predictor;
    const ElementArrays el = make_element_arrays(scene, lattice);
    Simulator sim(scene, lattice, el, cl, o.plan);
    const double sps = time_steps(sim, target_s);
    const std::size_t n = lattice.element_count();
    // A step moves the bytes of the elements it steps: held ones are only read as neighbours
    // (most of the phantom's rigid chest wall not at all).
    const std::size_t n_free = n - el.held_count;
    const std::size_t real_size = c.precision == Precision::Double ? 8 : 4;
    // one stage for Euler, and for relaxation with the element's mass scale
    const bool heun = c.integrator == "heun";
    const double bytes = (heun ? 1.0 : 0.5) * heun_bytes_per_element(real_size, c.law, sim.pred_packed()) +
                         (c.integrator == "relaxation" ? double(real_size) : 0.0);
    const double effective = bytes * double(n_free) * sps;
    const char* prec = c.precision == Precision::Double ? "double" : "float";
    std::printf("%-12s %9zu elements (%zu free)  %-11s %-16s %-6s %10.1f steps/s  %6.2f ns/element-step  %5.1f%% of copy bandwidth\n",
                c.name.c_str(), n, n_free, c.law.c_str(), c.integrator.c_str(), prec, sps, 1e9 / (sps * double(n)), 100 * effective / bandwidth);
    std::fflush(stdout);
    const std::optional<double> floor_sps = gather_floor_rate(cl, sim, scene, lattice, el, target_s);
    if (floor_sps)
      std::printf("    gather floor %.1f steps/s (the step's reads and writes alone): the step at %.1f%% of it\n", *floor_sps,
                  100 * sps / *floor_sps);
    nlohmann::json row = {{"model", c.name}, {"elements", n}, {"free_elements", n_free}, {"law", c.law}, {"integrator", c.integrator}, {"precision", prec},
                          {"steps_per_s", sps}, {"bytes_per_element_step", bytes}, {"effective_bandwidth_gb_s", effective / 1e9},
                          {"fraction_of_copy_bandwidth", effective / bandwidth},
                          {"device_bytes_per_element", double(sim.device_bytes()) / double(n)},
                          {"volume_launches_per_projection", c.volume ? sim.volume_launches() : 0},
                          // what ran: the one-launch step projects whatever the option says
                          {"volume_predictor", !c.volume                         ? nlohmann::json()
                                               : sim.volume_predictor_pressure() ? nlohmann::json("pressure")
                                                                                 : nlohmann::json("projection")},
                          {"force_split", sim.force_split()}, {"persistent_step", sim.persistent_step()},
                          {"stress_pair", sim.stress_pair()}, {"stress_pass_elements", sim.stress_pass_elements()},
                          {"lanes_kernels", sim.lanes()},
                          // elements on the short connection loop (docs/PERFORMANCE.md)
                          {"uniform_loop_elements", sim.uniform_elements()},
                          {"step_list", sim.step_list()},
                          // Heun's predicted stage packed (docs/PERFORMANCE.md)
                          {"pred_packed", sim.pred_packed()},
                          // Heun's corrector over the blocks last to first (docs/PERFORMANCE.md)
                          {"correct_reverse", sim.correct_reverse()},
                          // the stepping kernels' work-group size, 0: the device's choice (docs/PERFORMANCE.md)
                          {"step_work_group", sim.step_work_group()},
                          {"dashpot_ratio", scene.solver.dashpot_ratio},
                          // the same kernels without their arithmetic (engine/bench/gather_floor.hpp)
                          {"gather_floor_steps_per_s", floor_sps ? nlohmann::json(*floor_sps) : nlohmann::json()},
                          {"fraction_of_gather_floor", floor_sps ? nlohmann::json(sps / *floor_sps) : nlohmann::json()}};
    csv << c.name << "," << n << "," << c.law << "," << c.integrator << "," << prec << "," << sps << "," << 1e9 / (sps * double(n)) << ","
        << bytes << "," << effective / 1e9 << "," << effective / bandwidth << "," << double(sim.device_bytes()) / double(n)
        << "," << n_free << ",";
    if (floor_sps)
      csv << *floor_sps << "," << sps / *floor_sps;
    else
      csv << ",";
    csv << "," << scene.solver.dashpot_ratio << "\n";
    if (o.profile) {
      // Which side sets the pace: the host's launches (enqueue time close to the step) or the
      // device (its time alone close to the step).
      const double host_s = host_enqueue_per_step(sim);
      // 64 steps of at most 8 launches: NVIDIA's queue takes 512 without blocking the host (it
      // blocks somewhere between 512 and 2,048)
      const std::int64_t held_steps = 64;
      const DeviceAlone device = device_time_per_step(cl, sim, held_steps, host_s);
      char device_text[160] = "not measured (the holding kernel's own time varied by more than the steps took)";
      if (device.seconds_per_step)
        std::snprintf(device_text, sizeof device_text, "%.2f us/step (%lld steps behind a held queue, median of 3%s)",
                      1e6 * *device.seconds_per_step, (long long)held_steps,
                      device.host_ahead ? "" : "; the host fell behind: an upper bound");
      std::printf("    host enqueue %.2f us/step (16-step batch), device alone %s, timed %.2f us/step\n", 1e6 * host_s,
                  device_text, 1e6 / sps);
      row["host_enqueue_us_per_step"] = 1e6 * host_s;
      row["device_alone_us_per_step"] = device.seconds_per_step ? nlohmann::json(1e6 * *device.seconds_per_step) : nlohmann::json();
      row["device_alone_host_ahead"] = device.host_ahead;
      print_kernel_profile(cl, scene, lattice, el, sps, o.plan);
    }
    rows.push_back(row);
  }
  result.rows = rows;
  result.csv = csv.str();
  return result;
}

}  // namespace vb::app
