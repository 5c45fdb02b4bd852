// voxbreast bench [--quick] --out DIR — speed against accuracy: standard scenes run to equilibrium
// over the knobs users turn (law, integrator, precision, resolution, time step, volume
// constraint), each measured against its scene's reference solution; plus steps/s of cube models
// against the device's copy bandwidth (--sizes). Writes bench.json, bench.csv (and
// throughput.csv); with --haptic the haptic rate of a probe pressing a block. Design, reference
// and error measures: docs/BENCHMARKS.md.
//   voxbreast bench --quick --out out/bench --phantom data-samples/phantom/scene.toml
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>

#include "apps/bench_throughput.hpp"
#include "apps/commands.hpp"
#include "apps/progress.hpp"
#include "apps/simulation_pipeline.hpp"
#include "engine/bench/bench_knobs.hpp"
#include "engine/bench/bench_table.hpp"
#include "engine/bench/standard_study.hpp"
#include "engine/error.hpp"
#include "engine/haptic/haptic_bench.hpp"
#include "engine/haptic/haptic_report.hpp"
#include "engine/lattice/voxelise.hpp"
#include "io/atomic_file.hpp"
#include "voxbreast/config.hpp"

namespace vb::app {
namespace {

const char* kDefaultPhantom = "data-samples/phantom/scene.toml";

struct BenchOptions {
  std::string out, device, phantom;
  bool quick = false, large = false, no_study = false, dry_run = false, haptic = false;
  bool volume = false, profile = false;  ///< throughput: block_volume cases; per-kernel device times
  std::string volume_predictor = "pressure";  ///< throughput: [volume] predictor of the volume cases
  bool breast = false;        ///< throughput: the phantom at ~36k elements too
  bool breast_large = false;  ///< throughput: the phantom at ~1.5M elements too
  std::vector<long> breast_elements;  ///< throughput: the phantom resampled to about these counts
  std::vector<int> sizes;  ///< throughput blocks (edge lengths in elements)
  double cube_dashpot_ratio = SolverSpec{}.dashpot_ratio;  ///< throughput: the cubes' connection dashpots ζ
  std::vector<int> haptic_elements = {10000};  ///< haptic-rate blocks (about this many elements)
  double haptic_seconds = 3;
  std::vector<std::string> laws, integrators, scenes;
  std::vector<std::string> jobs;  ///< scenes run end to end like `simulate`, each phase timed
  std::string plan;  ///< throughput: launch-plan overrides, "key=value,..." (engine/sim/launch_plan.hpp)
};

std::string utc_date() {
  const std::time_t now = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d", std::gmtime(&now));
  return text;
}

/// One progress line per run.
void print_row(std::size_t index, std::size_t total, const bench::CaseResult& r) {
  const bench::BenchCase& c = r.knobs;
  std::printf("[%3zu/%zu] %-13s %-11s %-16s %-6s d%d dt×%-4g %-6s %9zu el  ", index, total, c.scene.c_str(),
              c.law.c_str(), c.integrator.c_str(), bench::precision_name(c.precision), c.downsample, c.dt_factor,
              c.part == "reference" ? "REF" : c.volume ? "vol" : "", r.elements);
  if (r.status == "unstable" || r.status == "failed") {
    std::printf("%s: %s\n", r.status == "unstable" ? "UNSTABLE" : "FAILED", r.message.c_str());
  } else {
    std::printf("%8lld steps %8.2f s %9.0f steps/s  err max %.2e rms %.2e mm  dV %+.3f%%%s\n", (long long)r.steps,
                r.wall_s, r.seconds_per_step > 0 ? 1 / r.seconds_per_step : 0.0, 1e3 * r.error_max_m,
                1e3 * r.error_rms_m, 100 * r.volume_change, r.status == "ok" ? "" : "  (not converged)");
  }
  std::fflush(stdout);
}

nlohmann::json describe_scenes(const bench::StudyPlan& plan) {
  nlohmann::json scenes = nlohmann::json::array();
  for (const bench::BenchScene& s : plan.scenes) {
    nlohmann::json elements = nlohmann::json::object();
    std::set<int> levels;
    for (const bench::BenchCase& c : plan.cases)
      if (c.scene == s.name) levels.insert(c.downsample);
    for (int d : levels) elements[std::to_string(d)] = build_lattice(s.volume, d).element_count();
    nlohmann::json j = {{"name", s.name}, {"spacing_mm", 1e3 * s.volume.spacing_m}, {"elements_by_downsample", elements},
                        {"equilibrium_tolerance", s.scene.stop.equilibrium}};
    if (s.column) j["closed_form_sag_mm"] = 1e3 * s.column->sag_m();
    scenes.push_back(j);
    std::printf("scene %-13s %.2f mm:", s.name.c_str(), 1e3 * s.volume.spacing_m);
    for (auto& [d, n] : elements.items()) std::printf("  downsample %s → %zu elements", d.c_str(), n.get<std::size_t>());
    std::printf("\n");
  }
  return scenes;
}

/// The haptic-rate section (docs/BENCHMARKS.md, "Haptic rate"): a probe pressing a block, force
/// output at 1 kHz from a loop decoupled from the deformation updates.
nlohmann::json run_haptic_bench(const ClContext& cl, const BenchOptions& o) {
  nlohmann::json rows = nlohmann::json::array();
  for (const int elements : o.haptic_elements) {
    const Scene scene = haptic_bench_scene(std::size_t(elements), Precision::Float);
    const Lattice lattice = build_lattice(voxelise_shapes(scene), 1);
    const ElementArrays el = make_element_arrays(scene, lattice);
    HapticProbe probe(scene, lattice, el, cl);
    HapticLoopOptions loop;
    loop.rate_hz = 1000;
    loop.seconds = o.haptic_seconds;
    const HapticLoopResult r = run_haptic_loop(probe, haptic_bench_press(scene, loop.seconds), loop);
    nlohmann::json row = haptic_summary_json(r, loop, probe, lattice.element_count());
    std::printf("haptic %7zu el: force %7.1f Hz (interval mean %.3f p99 %.3f max %.3f ms, %lld late%s); "
                "%lld updates %.1f Hz, %.0f steps/s%s\n",
                lattice.element_count(), r.achieved_rate_hz, 1e3 * r.intervals.mean_s, 1e3 * r.intervals.p99_s,
                1e3 * r.intervals.max_s, (long long)r.intervals.missed, r.realtime ? ", real-time priority" : "",
                (long long)r.updates, r.update_rate_hz, row["steps_per_second"].get<double>(),
                r.blown_up ? "  BLEW UP" : r.folded ? "  FOLDED" : "");
    if (r.folded) std::printf("  warning: %s\n", haptic_fold_warning(r).c_str());
    std::fflush(stdout);
    rows.push_back(row);
  }
  return rows;
}

/// The main job end to end (`voxbreast simulate`) on each --job scene, into OUT/job_N/: the time
/// of each phase (summary.json `timings`) and the image outputs' peak host memory over the CT's
/// size as floats.
nlohmann::json run_job_bench(const ClContext& cl, const BenchOptions& o) {
  nlohmann::json rows = nlohmann::json::array();
  Progress bar(true);
  for (std::size_t n = 0; n < o.jobs.size(); ++n) {
    const auto command_start = std::chrono::steady_clock::now();
    const Scene scene = load_scene(o.jobs[n], "");
    const std::string dir = o.out + "/job_" + std::to_string(n + 1);
    const OutputDir job_dir(dir);
    SimulationOptions options;
    options.command_start = command_start;
    show_progress(bar, scene, options, "job " + std::to_string(n + 1) + " ");
    const SimulationReport report = simulate_scene(scene, cl, dir, options);
    bar.finish();
    const nlohmann::json summary = nlohmann::json::parse(std::ifstream(dir + "/summary.json"));
    const PhaseTimings& t = report.timings;
    nlohmann::json row = {{"scene", o.jobs[n]}, {"elements", report.summary.elements},
                          {"steps", report.summary.steps}, {"converged", report.summary.converged},
                          {"timings", summary.at("timings")}};
    double memory_ratio = NAN;
    if (summary.contains("image_outputs") && summary["image_outputs"].contains("host_memory")) {
      const nlohmann::json& m = summary["image_outputs"]["host_memory"];
      memory_ratio = (m.at("peak_bytes").get<double>() - m.at("before_bytes").get<double>()) /
                     m.at("ct_float_bytes").get<double>();
      row["ct_voxels"] = m.at("ct_float_bytes").get<double>() / 4;
      row["image_outputs_peak_memory_over_ct_floats"] = memory_ratio;
    }
    std::printf("job %zu %s: %zu el, %lld steps; setup %.1f s, kernel build %.1f s, reference state %.1f s, solve %.1f s, "
                "reproducibility %.1f s, outputs %.1f s (image outputs %.1f s, peak memory %.2f × the CT's floats); "
                "total %.1f s\n",
                n + 1, o.jobs[n].c_str(), report.summary.elements, (long long)report.summary.steps, t.setup_s,
                t.kernel_build_s, t.reference_state_s, t.solve_s, t.reproducibility_s, t.outputs_s, t.image_outputs_s,
                memory_ratio, t.total_s);
    std::fflush(stdout);
    rows.push_back(row);
  }
  return rows;
}

int run_bench(BenchOptions o) {
  const auto start = std::chrono::steady_clock::now();
  const PlanOverrides plan = PlanOverrides::parse(o.plan);  // a bad override is refused before any output
  const OutputDir output_dir(o.out);
  if (o.phantom.empty()) {
    if (std::filesystem::exists(kDefaultPhantom)) o.phantom = kDefaultPhantom;
    else std::printf("note: %s not found; phantom scenes left out (give --phantom)\n", kDefaultPhantom);
  }
  const DeviceInfo device = select_device(o.device);
  std::printf("device: %s (%s)\n", device.name.c_str(), device.platform.c_str());

  nlohmann::json doc = {{"device", device.name}, {"platform", device.platform}, {"driver", device.driver},
                        {"fp64", device.fp64}, {"quick", o.quick}, {"date", utc_date()},
                        {"voxbreast_version", config::version}, {"git_commit", config::git_commit}};
  std::string study_csv = bench::csv_header();
  std::size_t failures = 0;
  // Rewritten after every run, so that a run cut short (a device time limit) keeps what it did.
  const auto write_outputs = [&] {
    doc["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    write_text_atomically(o.out + "/bench.json", doc.dump(2) + "\n");
    if (!o.no_study) write_text_atomically(o.out + "/bench.csv", study_csv);
  };
  std::unique_ptr<ClContext> cl;
  if (!o.dry_run && !o.jobs.empty()) {
    cl = std::make_unique<ClContext>(device);
    doc["jobs"] = run_job_bench(*cl, o);
    write_outputs();
  }
  // The cubes first: they are short, and kept when a long study is cut off by a time limit.
  if (!o.dry_run && o.haptic) {
    if (!cl) cl = std::make_unique<ClContext>(device);
    doc["haptic"] = run_haptic_bench(*cl, o);
    write_outputs();
  }
  const bool breast_any = o.breast || o.breast_large || !o.breast_elements.empty();
  if (!o.dry_run && (!o.sizes.empty() || breast_any || (!o.quick && o.no_study && !o.haptic && o.jobs.empty()))) {
    if (!cl) cl = std::make_unique<ClContext>(device);
    ThroughputOptions t;
    // 35,937 and 1,520,875 elements unless sizes are given; --breast alone times the breast alone
    t.sizes = !o.sizes.empty() || breast_any ? o.sizes : std::vector<int>{33, 115};
    t.quick = o.quick;
    t.volume = o.volume;
    t.volume_predictor =
        o.volume_predictor == "projection" ? VolumeSpec::Predictor::Projection : VolumeSpec::Predictor::Pressure;
    t.profile = o.profile;
    t.cube_dashpot_ratio = o.cube_dashpot_ratio;
    t.plan = plan;
    if (breast_any) {
      require(!o.phantom.empty(), "--breast, --breast-large and --breast-elements need the phantom's scene",
              "bench --breast", "give --phantom");
      t.phantom_scene = o.phantom;
      t.breast = o.breast;
      t.breast_large = o.breast_large;
      t.breast_elements = o.breast_elements;
      if (!o.integrators.empty()) t.breast_integrators = o.integrators;
    }
    if (!o.laws.empty()) t.laws = o.laws;
    const ThroughputResult tr = run_throughput(*cl, t);
    doc["copy_bandwidth_gb_s"] = tr.copy_bandwidth_gb_s;
    doc["throughput"] = tr.rows;
    write_text_atomically(o.out + "/throughput.csv", tr.csv);
    std::printf("wrote %s/throughput.csv\n", o.out.c_str());
    write_outputs();
  }
  if (!o.no_study) {
    bench::PlanOptions plan_options;
    plan_options.quick = o.quick;
    plan_options.large = o.large || (device.is_gpu && !o.quick);
    plan_options.phantom_scene = o.phantom;
    plan_options.scenes = o.scenes;
    plan_options.laws = o.laws;
    plan_options.integrators = o.integrators;
    bench::StudyPlan plan = bench::standard_plan(plan_options);
    doc["scenes"] = describe_scenes(plan);
    doc["reference"] = {{"integrator", "heun"}, {"precision", "double"}, {"downsample", 1},
                        {"dt_factor", plan.settings.reference_dt_factor},
                        {"tolerance_factor", plan.settings.reference_tolerance_factor}};
    std::set<std::string> reference_keys;
    for (const bench::BenchCase& c : plan.cases) reference_keys.insert(c.reference_key());
    const std::size_t total = plan.cases.size() + reference_keys.size();
    std::printf("%zu runs: %zu cases and %zu reference solutions\n", total, plan.cases.size(), reference_keys.size());
    if (o.dry_run) {
      for (const bench::BenchCase& c : plan.cases) std::printf("  %-10s %s\n", c.part.c_str(), c.knobs().c_str());
      return 0;
    }
    if (!cl) cl = std::make_unique<ClContext>(device);
    bench::TradeStudy study(*cl, plan.settings);
    for (bench::BenchScene& s : plan.scenes) study.add_scene(std::move(s));
    for (const bench::BenchCase& c : plan.cases) study.expect(c);
    doc["results"] = nlohmann::json::array();
    std::size_t index = 0;
    for (const bench::BenchCase& c : plan.cases) {
      for (const bench::CaseResult& r : study.run(c)) {
        print_row(++index, total, r);
        failures += r.status == "failed";
        doc["results"].push_back(bench::row_json(r));
        study_csv += bench::csv_row(r);
      }
      write_outputs();
    }
  }
  write_outputs();
  std::printf("wrote %s/bench.json%s (%.0f s)\n", o.out.c_str(), o.no_study ? "" : " and bench.csv",
              doc["wall_s"].get<double>());
  if (failures) std::printf("%zu runs failed (see 'message' in bench.csv)\n", failures);
  return 0;
}

}  // namespace

Command add_bench(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  auto* sub = app.add_subcommand("bench", "Speed against accuracy over laws, integrators, precision, resolution, "
                                          "time step and volume constraint; steps/s of cube models");
  sub->add_option("--out,-o", o->out, "output folder")->required();
  sub->add_option("--device,-d", o->device, "OpenCL device: gpu, cpu, an index or a name");
  sub->add_flag("--quick", o->quick, "the CI-sized study (under 2 minutes on 2 CPU cores)");
  sub->add_option("--phantom", o->phantom, std::string("scene.toml of the breast phantom (default ") + kDefaultPhantom + ")")
      ->check(CLI::ExistingFile);
  sub->add_option("--scenes", o->scenes, "only these scenes: column, phantom, phantom_large");
  sub->add_flag("--large", o->large, "add phantom_large (~1.5M elements; on by default on a GPU without --quick)");
  sub->add_option("--laws", o->laws, "material laws of the grid (linear, biphasic, neo-hookean, ogden; default all, --quick all but ogden)")
      ->check(CLI::IsMember(bench::law_names()));
  sub->add_option("--integrators", o->integrators, "only these integrators (the study; and the --breast-elements models, default heun)")->check(CLI::IsMember(bench::integrator_names()));
  sub->add_flag("--no-study", o->no_study, "skip the speed/accuracy study (throughput only)");
  sub->add_option("--sizes", o->sizes, "throughput: time cubes of these edge lengths in elements (e.g. 33 115)")
      ->check(CLI::Range(2, 1000));
  sub->add_flag("--breast", o->breast,
                "throughput: also time the breast phantom resampled to ~36k elements (models breast, breast_volume)");
  sub->add_flag("--breast-large", o->breast_large,
                "throughput: also time the breast phantom resampled to ~1.5M elements, linear springs (model breast_large)");
  sub->add_option("--breast-elements", o->breast_elements,
                  "throughput: also time the breast phantom resampled to about each of these element counts, "
                  "each of --laws (default linear) and --integrators (default heun) (model breast_resampled)")
      ->check(CLI::Range(1000L, 100000000L));
  sub->add_flag("--volume", o->volume, "throughput: also time each law with [volume] preserve = true (model block_volume)");
  sub->add_option("--dashpot-ratio", o->cube_dashpot_ratio,
                  "throughput: the cubes' connection dashpot ratio ζ (solver.dashpot_ratio; default 0.1; 0: global "
                  "damping only), to time what the dashpots cost")
      ->check(CLI::Range(0.0, 10.0));
  sub->add_option("--volume-predictor", o->volume_predictor,
                  "throughput: [volume] predictor of the --volume models: pressure (default) or projection, to time "
                  "the two ways Heun's predicted stage meets the constraint")
      ->check(CLI::IsMember({"pressure", "projection"}));
  sub->add_flag("--profile", o->profile, "throughput: print whether the host or the device sets the pace (host "
                                         "enqueue time, the device's time alone, the timed step) and the device time "
                                         "and launches per step of each kernel (a second run of each block on a "
                                         "profiling queue)");
  sub->add_option("--job", o->jobs,
                  "run this scene end to end like 'simulate' (into OUT/job_N/), timing each phase and the image "
                  "outputs' peak memory; repeatable")
      ->check(CLI::ExistingFile);
  sub->add_option("--plan", o->plan,
                  "throughput: launch-plan overrides to compare schedules on a device, e.g. lanes=0,step_list=1 "
                  "(keys in engine/sim/launch_plan.hpp; docs/PERFORMANCE.md)");
  sub->add_flag("--dry-run", o->dry_run, "list the scenes and cases without running them");
  sub->add_flag("--haptic", o->haptic, "haptic rate: a probe pressing a block, force output at 1 kHz (with "
                                       "--no-study: only this)");
  sub->add_option("--haptic-elements", o->haptic_elements, "haptic rate: blocks of about these element counts (default 10000)")
      ->check(CLI::Range(64, 100000000));
  sub->add_option("--haptic-seconds", o->haptic_seconds, "haptic rate: seconds per block (default 3)")
      ->check(CLI::Range(0.1, 600.0));
  return {sub, [o] { return run_bench(*o); }};
}

}  // namespace vb::app
