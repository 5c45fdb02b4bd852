#include "apps/fit_batch.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>

#include "apps/fit_pipeline.hpp"
#include "engine/error.hpp"
#include "engine/study/sweep.hpp"
#include "engine/study/sweep_devices.hpp"
#include "io/fit_file.hpp"
#include "io/scene_file.hpp"
#include "io/scene_overrides.hpp"
#include "io/toml_text.hpp"

namespace fs = std::filesystem;

namespace vb::app {
namespace {

struct BatchCase {
  std::string scene_path;  ///< as written in the CSV
  std::string truth_path;  ///< absolute, or empty
};

std::string read_file(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  require(in && fs::is_regular_file(path), "cannot read the " + what, path, "check the path");
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// CSV with a header naming `scene` (required) and `truth` (optional); one case per row.
std::vector<BatchCase> read_cases(const std::string& text, const std::string& path) {
  std::stringstream in(text);
  std::string line;
  std::vector<std::string> head;
  std::vector<BatchCase> cases;
  const auto fields = [](const std::string& l) {
    std::vector<std::string> out;
    std::stringstream s(l);
    std::string f;
    while (std::getline(s, f, ',')) {
      const auto b = f.find_first_not_of(" \t\r"), e = f.find_last_not_of(" \t\r");
      out.push_back(b == std::string::npos ? "" : f.substr(b, e - b + 1));
    }
    if (!l.empty() && l.back() == ',') out.emplace_back();  // getline drops a trailing empty field
    return out;
  };
  const fs::path base = fs::path(path).parent_path();
  int row = 0;
  while (std::getline(in, line)) {
    ++row;
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    if (head.empty()) {
      head = fields(line);
      require(!head.empty() && head[0] == "scene" && (head.size() == 1 || (head.size() == 2 && head[1] == "truth")),
              "the header must be 'scene' or 'scene,truth'", path + " row " + std::to_string(row));
      continue;
    }
    const std::vector<std::string> f = fields(line);
    require(f.size() == head.size() && !f[0].empty(), "expected " + std::to_string(head.size()) + " fields",
            path + " row " + std::to_string(row));
    BatchCase c;
    c.scene_path = f[0];
    if (f.size() > 1 && !f[1].empty())
      c.truth_path = fs::absolute(base / f[1]).lexically_normal().string();
    cases.push_back(c);
  }
  require(!cases.empty(), "the case list has no cases", path);
  return cases;
}

/// The scene with every relative data path (model and [fit]) made absolute, so the case
/// folder's scene.toml runs on its own.
std::string with_absolute_paths(std::string text, const std::string& source) {
  const fs::path base = fs::path(source).parent_path();
  std::vector<std::string> keys = scene_path_keys();
  for (const char* k : {"fit.dvf", "fit.landmarks", "fit.observed_labels", "fit.observed_surface", "fit.mask", "fit.sigma"})
    keys.push_back(k);
  // fit.observed_surface may be an array of files: its elements by 1-based index
  if (const toml::array* a = parse_toml_text(text, source)["fit"]["observed_surface"].as_array())
    for (std::size_t i = 1; i <= a->size(); ++i) keys.push_back("fit.observed_surface." + std::to_string(i));
  for (const std::string& key : keys) {
    const std::string value = scene_string_value(text, source, key);
    if (value.empty() || fs::path(value).is_absolute()) continue;
    const std::string absolute = fs::absolute(base / value).lexically_normal().string();
    text = apply_scene_overrides(text, source, {{key, toml_string_text(absolute), false}});
  }
  return text;
}

void copy_outputs(const std::string& from, const std::string& to) {
  for (const fs::directory_entry& e : fs::directory_iterator(from))
    if (e.is_regular_file() && e.path().filename().string()[0] != '.')
      fs::copy_file(e.path(), fs::path(to) / e.path().filename(), fs::copy_options::overwrite_existing);
}

}  // namespace

int run_fit_batch(const FitBatchOptions& o) {
  const std::string csv_text = read_file(o.cases_csv, "case list");
  const std::vector<BatchCase> cases = read_cases(csv_text, o.cases_csv);
  const fs::path base = fs::path(o.cases_csv).parent_path();

  SweepPlan plan;
  plan.scene_path = o.cases_csv;
  plan.scene_text = csv_text;
  SweepParameter scenes{"scene", false, {}};
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string path = fs::absolute(base / cases[i].scene_path).lexically_normal().string();
    scenes.values.push_back(toml_string_text(cases[i].scene_path));
    try {
      std::string text = with_absolute_paths(read_file(path, "scene file"), path);
      (void)parse_scene_text(text, path);  // every strict check, before any case runs
      (void)parse_fit_section(text, path);
      plan.case_scenes.push_back(std::move(text));
    } catch (const Error& e) {
      throw Error("case " + std::to_string(i + 1) + ": " + e.problem(), e.location(), e.hint());
    }
  }
  plan.grid = SweepGrid({scenes});

  MpiWorld world;
  const std::vector<std::unique_ptr<ClContext>> contexts = open_worker_contexts(o.devices, world);

  SweepOptions options;
  options.out_dir = o.out;
  options.outputs = "fit";
  options.stop_after = o.stop_after;
  options.retry_failed = o.retry_failed;
  options.workers = worker_names(contexts);
  const std::string rank_tag = world.size() > 1 ? "[rank " + std::to_string(world.rank()) + "] " : "";
  options.on_progress = [&](const SweepProgress& p) {
    if (p.kind != SweepProgress::Kind::Finished || o.quiet) return;
    std::printf("%scase %s  %-6s %7.1f s  %s%s\n", rank_tag.c_str(), p.id.c_str(), p.status.c_str(), p.wall_time_s,
                cases[p.index].scene_path.c_str(), p.error.empty() ? "" : ("\n    " + p.error).c_str());
    std::fflush(stdout);
  };
  const SweepOutcome outcome = run_sweep(plan, options, world, [&](const SweepCase& c, std::size_t worker) {
    // Iterations are checkpointed outside the case's working folder, which a killed run loses.
    const std::string progress_dir = o.out + "/progress/" + c.id;
    Scene scene = parse_scene_text(c.scene_text, c.final_dir + "/scene.toml");
    scene.source_path = c.final_dir + "/scene.toml";
    FitRunOptions fit;
    fit.plots = o.plots;
    fit.truth_path = cases[c.index].truth_path;
    try {
      fit_scene(scene, *contexts[worker], progress_dir, fit);
    } catch (const cl::Error& e) {
      throw Error("OpenCL call " + std::string(e.what()) + " failed: " + cl_status_name(e.err()), "case " + c.id);
    }
    copy_outputs(progress_dir, c.work_dir);
    fs::remove_all(progress_dir);
  });
  world.finalize();
  if (world.rank() != 0) return 0;
  const SweepTablesReport& t = outcome.tables;
  for (const std::string& w : outcome.warnings) std::fprintf(stderr, "voxbreast: warning: %s\n", w.c_str());
  if (!o.quiet && outcome.run.skipped)
    std::printf("%zu cases were finished before this run and were kept\n", outcome.run.skipped);
  std::printf("fit batch: %zu cases: %zu ok, %zu failed, %zu not run; wrote %s/metrics.csv\n", cases.size(), t.ok,
              t.failed, t.pending, o.out.c_str());
  if (t.pending) {
    std::printf("run the same command again to finish the batch\n");
    return 3;
  }
  return t.failed ? 4 : 0;
}

}  // namespace vb::app
