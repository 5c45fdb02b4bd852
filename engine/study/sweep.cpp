#include "engine/study/sweep.hpp"

#include <algorithm>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>

#include "engine/error.hpp"
#include "io/atomic_file.hpp"
#include "io/file_hash.hpp"
#include "io/scene_file.hpp"
#include "io/scene_overrides.hpp"

namespace fs = std::filesystem;

namespace vb {
namespace {

std::string read_scene_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in || !fs::is_regular_file(path)) throw Error("cannot read the scene file", path, "check the path");
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// Relative data paths (model.image, model.labels) → absolute, against the base scene's folder.
std::string with_absolute_paths(std::string text, const std::string& source, const fs::path& base_dir) {
  for (const std::string& key : scene_path_keys()) {
    const std::string value = scene_string_value(text, source, key);
    if (value.empty() || fs::path(value).is_absolute()) continue;
    const std::string absolute = fs::absolute(base_dir / value).lexically_normal().string();
    text = apply_scene_overrides(text, source, {{key, toml_string_text(absolute), false}});
  }
  return text;
}

/// SHA-256 of each input file or folder, by path: a resumed sweep whose data changed is refused.
nlohmann::json input_hashes(const std::vector<std::string>& files) {
  nlohmann::json hashes = nlohmann::json::object();
  for (const std::string& file : files) hashes[file] = content_sha256(file);
  return hashes;
}

}  // namespace

SweepPlan plan_sweep(const std::string& scene_path, std::vector<SweepParameter> parameters) {
  SweepPlan plan;
  plan.scene_path = scene_path;
  plan.scene_text = read_scene_text(scene_path);
  plan.grid = SweepGrid(std::move(parameters));
  const fs::path base_dir = fs::path(scene_path).parent_path();
  // Key problems (typos, indices) are the same in every case: report them without a case.
  if (plan.grid.size() > 0) (void)apply_scene_overrides(plan.scene_text, scene_path, plan.grid.overrides_of(0));
  for (std::size_t i = 0; i < plan.grid.size(); ++i) {
    std::string values;
    const std::vector<SceneOverride> overrides = plan.grid.overrides_of(i);
    for (const SceneOverride& o : overrides) values += (values.empty() ? "" : ", ") + o.key + " = " + o.value;
    const std::string which = "case " + std::to_string(i + 1) + (values.empty() ? "" : " (" + values + ")");
    try {
      std::string text = apply_scene_overrides(plan.scene_text, scene_path, overrides);
      text = with_absolute_paths(text, scene_path, base_dir);
      const Scene scene = parse_scene_text(text, scene_path);  // every strict check of a scene file
      for (const std::string* file : {&scene.model.image_path, &scene.model.labels_path})
        if (!file->empty()) plan.input_files.push_back(*file);
      for (const IndenterSpec& indenter : scene.indenters)
        if (!indenter.path_file.empty()) plan.input_files.push_back(indenter.path_file);
      plan.case_scenes.push_back(std::move(text));
    } catch (const Error& e) {
      throw Error(which + ": " + e.problem(), e.location(), e.hint());
    }
  }
  std::sort(plan.input_files.begin(), plan.input_files.end());
  plan.input_files.erase(std::unique(plan.input_files.begin(), plan.input_files.end()), plan.input_files.end());
  return plan;
}

SweepOutcome run_sweep(const SweepPlan& plan, const SweepOptions& options, const MpiWorld& world,
                       const SweepCaseRunner& run_case) {
  SweepOutcome outcome;
  const SweepFolder folder(options.out_dir, plan.grid.size());
  std::optional<SweepFolder::Lock> lock;
  std::exception_ptr error;
  if (world.rank() == 0) {
    try {
      ensure_output_dir(options.out_dir);
      lock.emplace(folder.path(".lock"));
      nlohmann::json definition = sweep_definition(plan.grid, plan.scene_path, plan.scene_text, options.outputs);
      definition["inputs"] = input_hashes(plan.input_files);
      outcome.warnings = folder.open(definition);
    } catch (...) {
      error = std::current_exception();
    }
  }
  if (!world.all(!error)) {
    if (error) std::rethrow_exception(error);
    throw Error("rank 0 could not open the sweep folder", options.out_dir, "see rank 0's message");
  }

  SweepRunOptions run;
  run.rank = world.rank();
  run.ranks = world.size();
  run.workers = options.workers;
  run.stop_after = options.stop_after;
  run.retry_failed = options.retry_failed;
  run.on_progress = options.on_progress;
  try {
    outcome.run = run_sweep_cases(folder, plan.grid, plan.case_scenes, run_case, run);
  } catch (...) {
    error = std::current_exception();
  }
  const bool all_ran = world.all(!error);  // every rank has finished its cases
  if (world.rank() == 0) outcome.tables = write_sweep_tables(folder, plan.grid);
  if (error) std::rethrow_exception(error);
  if (!all_ran) throw Error("another MPI rank stopped with an error", options.out_dir, "see that rank's message");
  return outcome;
}

}  // namespace vb
