#include "apps/fit_pipeline.hpp"

#include <algorithm>
#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <sstream>

#include "apps/simulation_setup.hpp"
#include "apps/sweep_plots.hpp"
#include "engine/error.hpp"
#include "engine/fit/forward_model.hpp"
#include "engine/fit/gauss_newton.hpp"
#include "engine/fit/deformed_labels.hpp"
#include "engine/fit/deformed_surface.hpp"
#include "engine/fit/initial_guess.hpp"
#include "engine/fit/mesh_distance.hpp"
#include "engine/fit/surface_observation.hpp"
#include "io/atomic_file.hpp"
#include "io/csv_table.hpp"
#include "io/fit_file.hpp"
#include "io/fit_landmarks_csv.hpp"
#include "io/nifti_io.hpp"
#include "io/stl_file.hpp"
#include "io/triangle_mesh_files.hpp"

namespace vb::app {
namespace {

using nlohmann::json;

/// JSON has no infinity: null stands for it
json finite_or_null(const std::vector<double>& values) {
  json out = json::array();
  for (const double x : values) out.push_back(std::isfinite(x) ? json(x) : json());
  return out;
}

json progress_to_json(const FitProgress& p) {
  json rows = json::array();
  for (const FitIteration& r : p.history)
    rows.push_back({{"iteration", r.iteration}, {"cost", r.cost}, {"data_cost", r.data_cost}, {"rms_mm", r.rms_mm},
                    {"within_1mm", r.within_1mm}, {"max_mm", r.max_mm}, {"lm_damping", r.lm_damping},
                    {"forward_solves", r.forward_solves}, {"wall_time_s", r.wall_time_s},
                    {"modulus_pa", r.modulus_pa}});
  return {{"modulus_pa", p.modulus_pa}, {"lower_log", p.lower_log}, {"upper_log", p.upper_log},
          {"lm_damping", p.lm_damping}, {"history", rows}, {"finished", p.finished}, {"stop_reason", p.stop_reason},
          {"log_standard_error", finite_or_null(p.log_standard_error)}};
}

FitProgress progress_from_json(const json& j) {
  FitProgress p;
  p.modulus_pa = j.at("modulus_pa").get<std::vector<double>>();
  p.lower_log = j.at("lower_log").get<std::vector<double>>();
  p.upper_log = j.at("upper_log").get<std::vector<double>>();
  p.lm_damping = j.at("lm_damping").get<double>();
  p.finished = j.at("finished").get<bool>();
  p.stop_reason = j.at("stop_reason").get<std::string>();
  if (j.contains("log_standard_error"))
    for (const json& x : j.at("log_standard_error"))
      p.log_standard_error.push_back(x.is_null() ? std::numeric_limits<double>::infinity() : x.get<double>());
  for (const json& r : j.at("history")) {
    FitIteration row;
    row.iteration = r.at("iteration");
    row.cost = r.at("cost");
    row.data_cost = r.at("data_cost");
    row.rms_mm = r.at("rms_mm");
    row.within_1mm = r.at("within_1mm");
    row.max_mm = r.value("max_mm", 0.0);
    row.lm_damping = r.at("lm_damping");
    row.forward_solves = r.at("forward_solves");
    row.wall_time_s = r.at("wall_time_s");
    row.modulus_pa = r.at("modulus_pa").get<std::vector<double>>();
    p.history.push_back(row);
  }
  return p;
}

std::string history_csv(const FitProgress& p, const FitRegions& regions) {
  std::vector<std::string> head = {"iteration", "cost", "data_cost", "rms_mm", "within_1mm", "lm_damping",
                                   "forward_solves", "wall_time_s", "max_mm"};
  const bool columns = regions.size() <= 64;  // per-region columns only while readable
  if (columns)
    for (const std::string& n : regions.names) head.push_back("E_" + n + "_pa");
  std::string text = csv_line(head);
  for (const FitIteration& r : p.history) {
    std::vector<std::string> f = {std::to_string(r.iteration), shortest_number_text(r.cost),
                                  shortest_number_text(r.data_cost), shortest_number_text(r.rms_mm),
                                  shortest_number_text(r.within_1mm), shortest_number_text(r.lm_damping),
                                  std::to_string(r.forward_solves), shortest_number_text(r.wall_time_s),
                                  shortest_number_text(r.max_mm)};
    if (columns)
      for (double E : r.modulus_pa) f.push_back(shortest_number_text(E));
    text += csv_line(f);
  }
  return text;
}

Observation load_observation(const FitSpec& fit, const Lattice& lattice) {
  Observation obs;
  if (!fit.dvf_path.empty()) {
    std::vector<float> field;
    const ImageVolume grid = read_nifti_displacement(fit.dvf_path, field);
    obs = observation_from_field(lattice, grid, field, fit.sigma_m);
    if (!fit.landmarks_path.empty()) {
      const Observation marks = observation_from_landmarks(lattice, read_fit_landmarks(fit.landmarks_path), fit.sigma_m);
      for (std::size_t e = 0; e < marks.weight_per_m2.size(); ++e) {
        if (marks.weight_per_m2[e] == 0) continue;  // a landmark overrides the field in its element
        obs.weight_per_m2[e] = marks.weight_per_m2[e];
        for (int a = 0; a < 3; ++a) obs.displacement_m[3 * e + a] = marks.displacement_m[3 * e + a];
      }
    }
  } else {
    obs = observation_from_landmarks(lattice, read_fit_landmarks(fit.landmarks_path), fit.sigma_m);
  }
  if (!fit.mask_path.empty()) apply_mask(obs, lattice, read_nifti(fit.mask_path));
  if (!fit.sigma_path.empty()) apply_sigma_image(obs, lattice, read_nifti(fit.sigma_path));
  require(obs.observed_elements() > 0, "no element is observed", "fit", "check the mask and the observation's grid");
  return obs;
}

/// Whether an empty lattice voxel at a world point is the body's outside: the CT there is below
/// −500 HU; outside the CT (a crop edge) it is not. Shape models: every empty voxel is air.
std::function<bool(const Eigen::Vector3d&)> air_test(const PreparedModel& model) {
  if (!model.ct) return [](const Eigen::Vector3d&) { return true; };
  const ImageVolume& ct = *model.ct;
  const Eigen::Matrix4d to_index = ct.affine_lps_m.inverse();
  return [&ct, to_index](const Eigen::Vector3d& p) {
    const Eigen::Vector3d q = (to_index * p.homogeneous()).head<3>();
    const int i = int(std::lround(q.x())), j = int(std::lround(q.y())), k = int(std::lround(q.z()));
    if (i < 0 || j < 0 || k < 0 || i >= ct.dims[0] || j >= ct.dims[1] || k >= ct.dims[2]) return false;
    return ct.values[ct.linear_index(i, j, k)] < -500.0f;
  };
}

/// The surface observation: boundaries of a label map (fit.observed_labels, regions
/// fit.observed_label_values) or surface meshes (fit.observed_surface, one region each from
/// fit.observed_surface_values), matched by the model's boundary faces.
std::unique_ptr<SurfaceData> load_surface_observation(const FitSpec& fit, const Scene& scene, const PreparedModel& model) {
  const bool meshes = !fit.observed_surface_paths.empty();
  const std::string key = meshes ? "fit.observed_surface" : "fit.observed_labels";
  require(fit.mask_path.empty() && fit.sigma_path.empty(), "fit.mask and fit.sigma apply to displacement observations",
          key, "leave them out; fit.sigma_mm is the surface distance uncertainty");
  std::vector<bool> free(model.lattice.element_count());
  for (std::size_t e = 0; e < free.size(); ++e) free[e] = model.elements.inverse_mass[e] != 0;
  if (!meshes) {
    const ImageVolume labels = read_nifti(fit.observed_labels_path);
    const std::vector<SurfaceRegion> regions = surface_regions(scene, model.lattice, fit.observed_label_values);
    return std::make_unique<SurfaceData>(labels, model.lattice, regions, free, air_test(model), fit.sigma_m);
  }
  std::vector<SurfaceRegion> regions;
  std::vector<std::unique_ptr<SurfaceDistance>> observed;
  for (std::size_t i = 0; i < fit.observed_surface_paths.size(); ++i) {
    const std::vector<SurfaceRegion> one =
        surface_regions(scene, model.lattice, {fit.observed_surface_values[i]}, "fit.observed_surface_values");
    for (const SurfaceRegion& r : regions)
      require(r.name != one[0].name, "two surfaces of region " + r.name, "fit.observed_surface_values",
              "give each boundary once");
    regions.push_back(one[0]);
    observed.push_back(std::make_unique<MeshSignedDistance>(read_stl(fit.observed_surface_paths[i]),
                                                            fit.observed_surface_paths[i]));
  }
  return std::make_unique<SurfaceData>(std::move(observed), model.lattice, regions, free, air_test(model), fit.sigma_m,
                                       "fit.observed_surface");
}

/// The element map on the lattice's own grid (world affine of the lattice), `outside` elsewhere.
void write_element_map(const std::string& path, const Lattice& lattice, const std::vector<double>& values) {
  ImageVolume image;
  image.dims = lattice.dims;
  image.affine_lps_m = lattice.affine();
  image.values.assign(std::size_t(lattice.dims[0]) * lattice.dims[1] * lattice.dims[2], 0.0f);
  for (std::size_t e = 0; e < lattice.element_count(); ++e) image.values[lattice.voxel_of_element[e]] = float(values[e]);
  write_nifti(path, image, NiftiType::Float32);
}

/// The lattice's own grid (values empty): element e sits at voxel voxel_of_element[e].
ImageVolume lattice_grid(const Lattice& lattice) {
  ImageVolume grid;
  grid.dims = lattice.dims;
  grid.affine_lps_m = lattice.affine();
  return grid;
}

/// Held elements (anchors, rigid tissue) do not move in any model: they are not evidence.
void unobserve_held(Observation& obs, const ElementArrays& elements) {
  for (std::size_t e = 0; e < obs.weight_per_m2.size(); ++e)
    if (elements.inverse_mass[e] == 0) obs.weight_per_m2[e] = 0;
}

/// The warm-start state beside checkpoint.json: raw doubles (from, then to), named by iteration
/// so the JSON, written after it, always names a complete file.
void write_state(const std::string& path, const FitProgress& p) {
  std::string bytes;
  for (const std::vector<double>* v : {&p.state_from_m, &p.state_to_m, &p.state_rest_m})
    bytes.append(reinterpret_cast<const char*>(v->data()), sizeof(double) * v->size());
  write_text_atomically(path, bytes);
}

/// `rest`: the state holds rest offsets too (fit.unloaded_reference)
void read_state(const std::string& path, std::size_t values, bool rest, FitProgress& p) {
  std::ifstream in(path, std::ios::binary);
  std::vector<double> all((rest ? 3 : 2) * values);
  in.read(reinterpret_cast<char*>(all.data()), std::streamsize(sizeof(double) * all.size()));
  require(bool(in), "the fit's saved state is missing or short", path, "delete the folder to start the fit over");
  const auto part = [&](int i) {
    return std::vector<double>(all.begin() + std::ptrdiff_t(i * values), all.begin() + std::ptrdiff_t((i + 1) * values));
  };
  p.state_from_m = part(0);
  p.state_to_m = part(1);
  if (rest) p.state_rest_m = part(2);
}

std::string fingerprint(const Scene& scene) {
  return std::to_string(std::hash<std::string>{}(scene.source_text));
}

}  // namespace

json fit_scene(const Scene& scene, const ClContext& cl, const std::string& dir, const FitRunOptions& options) {
  const FitSpec fit = parse_fit_section(scene.source_text, scene.source_path);
  ensure_output_dir(dir);
  const PreparedModel model = prepare_model(scene, &cl.info);
  const FitRegions regions = make_fit_regions(fit, scene, model.lattice);
  const ForwardModel forward(scene, model.lattice, regions, fit, cl);
  std::optional<Observation> obs;  // displacements, or
  std::unique_ptr<SurfaceData> surface;  // boundaries of a label map
  std::unique_ptr<FitData> displacements;
  if (fit.observed_labels_path.empty() && fit.observed_surface_paths.empty()) {
    obs = load_observation(fit, model.lattice);
    unobserve_held(*obs, model.elements);
    require(obs->observed_elements() > 0, "every observed element is held", "fit");
    displacements = std::make_unique<DisplacementData>(*obs);
  } else {
    surface = load_surface_observation(fit, scene, model);
  }
  const FitData& data = surface ? static_cast<const FitData&>(*surface) : *displacements;

  FitProblem problem;
  problem.model = &forward;
  problem.data = &data;
  problem.observation = obs ? &*obs : nullptr;
  problem.spec = fit;
  std::tie(problem.min_pa, problem.max_pa) = modulus_bounds(fit, scene, model.lattice, regions);
  std::string initial_rule = "materials";
  if (fit.initial == FitSpec::Initial::Hu && model.ct) {
    problem.initial_pa = moduli_from_hu(scene, model.lattice, regions, element_hu(model.lattice, *model.ct));
    initial_rule = "hu";
  } else {
    problem.initial_pa = moduli_from_materials(scene, model.lattice, regions);
  }
  for (double& E : problem.initial_pa) E = std::clamp(E, problem.min_pa, problem.max_pa);

  const std::string checkpoint_path = dir + "/checkpoint.json";
  FitProgress progress;
  if (std::filesystem::exists(checkpoint_path)) {
    std::ifstream in(checkpoint_path);
    const json saved = json::parse(in);
    require(saved.value("fingerprint", "") == fingerprint(scene) && saved.value("regions", std::size_t(0)) == regions.size(),
            "the folder holds the checkpoint of another fit", checkpoint_path,
            "use another --out folder or delete it to start over");
    progress = progress_from_json(saved.at("progress"));
    if (const std::string state = saved.value("state", ""); !state.empty())
      read_state(dir + "/" + state, 3 * forward.lattice().element_count(), forward.unloaded_reference(), progress);
  }
  const std::size_t done_before = progress.history.size();
  std::size_t reported = done_before;
  struct Stop {};
  const FitCheckpoint checkpoint = [&](const FitProgress& p) {
    const std::string state = p.state_to_m.empty() ? "" : "state-" + std::to_string(p.history.size()) + ".bin";
    if (!state.empty()) write_state(dir + "/" + state, p);
    json j = {{"fingerprint", fingerprint(scene)}, {"regions", regions.size()}, {"progress", progress_to_json(p)},
              {"state", state}};
    write_text_atomically(checkpoint_path, j.dump(1));
    for (const auto& f : std::filesystem::directory_iterator(dir)) {  // older states
      const std::string name = f.path().filename().string();
      if (name.rfind("state-", 0) == 0 && name != state) std::filesystem::remove(f.path());
    }
    write_text_atomically(dir + "/history.csv", history_csv(p, regions));
    if (options.on_iteration && p.history.size() > reported) options.on_iteration(p.history.back());
    reported = p.history.size();
    if (!p.finished && options.stop_after_iterations > 0 &&
        p.history.size() >= done_before + std::size_t(options.stop_after_iterations))
      throw Stop{};
  };
  bool stopped = false;
  if (!progress.finished) {
    try {
      progress = fit.method == FitSpec::Method::GaussNewton ? run_gauss_newton(problem, progress, checkpoint)
                                                            : run_bisection(problem, progress, checkpoint);
    } catch (const Stop&) {
      stopped = true;
    }
  }
  if (stopped) return {{"finished", false}};
  // Finished: the warm-start state is no longer needed.
  progress.state_from_m.clear();
  progress.state_to_m.clear();
  progress.state_rest_m.clear();
  write_text_atomically(checkpoint_path, json({{"fingerprint", fingerprint(scene)}, {"regions", regions.size()},
                                               {"progress", progress_to_json(progress)}, {"state", ""}})
                                             .dump(1));
  for (const auto& f : std::filesystem::directory_iterator(dir))
    if (f.path().filename().string().rfind("state-", 0) == 0) std::filesystem::remove(f.path());

  // Final outputs from the result's forward solve.
  const std::vector<double>& E = progress.history.back().modulus_pa;
  const ForwardSolution final_solution = forward.solve(E);
  const std::vector<double> change = final_solution.change_m();
  const ResidualStats stats = data.stats(change);
  const std::vector<double> element_E = forward.element_modulus(E);
  write_element_map(dir + "/elasticity.nii.gz", model.lattice, element_E);
  {
    std::vector<float> field(3 * std::size_t(model.lattice.dims[0]) * model.lattice.dims[1] * model.lattice.dims[2], 0.0f);
    for (std::size_t e = 0; e < model.lattice.element_count(); ++e)
      for (int a = 0; a < 3; ++a) field[3 * std::size_t(model.lattice.voxel_of_element[e]) + a] = float(change[3 * e + a]);
    write_nifti_displacement(dir + "/displacement.nii.gz", lattice_grid(model.lattice), field);
  }
  std::vector<double> residual_mm(model.lattice.element_count(), 0.0);
  if (surface) {  // the largest |surface distance| of each element's faces
    residual_mm = surface->element_distance(change, model.lattice.element_count());
    for (double& x : residual_mm) x *= 1e3;
  } else {
    for (std::size_t e = 0; e < residual_mm.size(); ++e)
      if (obs->weight_per_m2[e] > 0)
        residual_mm[e] = 1e3 * std::hypot(change[3 * e] - obs->displacement_m[3 * e],
                                          change[3 * e + 1] - obs->displacement_m[3 * e + 1],
                                          change[3 * e + 2] - obs->displacement_m[3 * e + 2]);
  }
  write_element_map(dir + "/residual_mm.nii.gz", model.lattice, residual_mm);

  // relative_standard_error: the Cramér–Rao bound of ln E (empty without a Jacobian; inf: undetermined)
  std::string regions_text = csv_line({"region", "elements", "initial_E_pa", "fitted_E_pa", "relative_standard_error"});
  for (std::size_t r = 0; r < regions.size(); ++r)
    regions_text += csv_line({regions.names[r], std::to_string(regions.element_count[r]),
                              shortest_number_text(problem.initial_pa[r]), shortest_number_text(E[r]),
                              r < progress.log_standard_error.size() ? shortest_number_text(progress.log_standard_error[r]) : ""});
  write_text_atomically(dir + "/regions.csv", regions_text);

  const FitIteration& first = progress.history.front();
  const FitIteration& last = progress.history.back();
  json regions_json = json::object();
  if (regions.size() <= 64)
    for (std::size_t r = 0; r < regions.size(); ++r)
    {
      regions_json[regions.names[r]] = {{"elements", regions.element_count[r]}, {"initial_E_pa", problem.initial_pa[r]},
                                        {"fitted_E_pa", E[r]}};
      if (r < progress.log_standard_error.size()) {  // Cramér–Rao bound (Gauss-Newton's last Jacobian)
        const double se = progress.log_standard_error[r];
        regions_json[regions.names[r]]["relative_standard_error"] = std::isfinite(se) ? json(se) : json();
      }
    }
  json summary = {
      {"finished", true},
      {"scene", scene.source_path},
      {"method", fit.method == FitSpec::Method::GaussNewton ? "gauss-newton" : "bisection"},
      {"regions_kind", fit.regions == FitSpec::Regions::Labels ? "labels"
                       : fit.regions == FitSpec::Regions::Blocks ? "blocks" : "elements"},
      {"regions", regions.size()},
      {"elements", model.lattice.element_count()},
      {"observation", data.kind()},
      {"observed_elements", obs ? obs->observed_elements() : 0},
      {"unloaded_reference", forward.unloaded_reference()},
      {"initial_guess", initial_rule},
      {"bounds_pa", {problem.min_pa, problem.max_pa}},
      {"iterations", int(progress.history.size()) - 1},
      {"forward_solves", last.forward_solves},
      {"wall_time_s", last.wall_time_s},
      {"stop_reason", progress.stop_reason},
      {"device", cl.info.name},
      {"precision", scene.solver.precision == Precision::Double ? "double" : "float"},
      {"batch", std::min(forward.batch_size(), regions.size())},  // copies per batched simulator
      {"jacobian_wall_time_s", forward.batch_wall_s()},  // this run's perturbed solves (timing.csv, not metrics.csv)
      {"initial", {{"cost", first.cost}, {"rms_mm", first.rms_mm}, {"within_1mm", first.within_1mm}}},
      {"final", {{"cost", last.cost}, {"rms_mm", stats.rms_m * 1e3}, {"mean_mm", stats.mean_m * 1e3},
                 {"p95_mm", stats.p95_m * 1e3}, {"max_mm", stats.max_m * 1e3}, {"within_1mm", stats.within_1mm}}},
      {"modulus_pa", regions_json},
  };
  {  // where the Jacobians' time went (docs/FIT.md, "Batched solves")
    const JacobianTiming& t = forward.jacobian_timing();
    summary["jacobian_timing"] = {{"jacobians", t.jacobians}, {"columns", t.columns}, {"simulators", t.simulators},
                                  {"setup_s", t.setup_s}, {"upload_s", t.upload_s}, {"relax_s", t.relax_s},
                                  {"readback_s", t.readback_s}, {"steps", t.steps}, {"element_steps", t.element_steps},
                                  {"most_steps_per_simulator", t.most_column_steps}};
  }
  if (forward.unloaded_reference())  // the fixed point's relaxation solves, all forward solves together
    summary["reference_state_solves"] = forward.reference_solves();
  if (surface) {
    json per_region = json::object();
    const std::vector<std::size_t> faces = surface->faces_per_region();
    for (std::size_t r = 0; r < faces.size(); ++r) per_region[surface->regions()[r].name] = faces[r];
    const json path = fit.observed_surface_paths.empty() ? json(fit.observed_labels_path)
                      : fit.observed_surface_paths.size() == 1 ? json(fit.observed_surface_paths[0])
                                                               : json(fit.observed_surface_paths);
    summary["surface"] = {{"source", fit.observed_surface_paths.empty() ? "label map" : "surface mesh"}, {"path", path}, {"faces", surface->points()}, {"faces_per_region", per_region},
                          {"initial", {{"rms_mm", first.rms_mm}, {"max_mm", first.max_mm}, {"within_1mm", first.within_1mm}}},
                          {"final", {{"rms_mm", stats.rms_m * 1e3}, {"mean_mm", stats.mean_m * 1e3}, {"p95_mm", stats.p95_m * 1e3},
                                     {"max_mm", stats.max_m * 1e3}, {"within_1mm", stats.within_1mm}}}};
  }
  if (!options.truth_path.empty()) {
    std::vector<float> field;
    const ImageVolume grid = read_nifti_displacement(options.truth_path, field);
    Observation truth = observation_from_field(model.lattice, grid, field, fit.sigma_m);
    for (std::size_t e = 0; e < truth.weight_per_m2.size(); ++e)  // the fit's elements; surfaces: every free one
      if (obs ? obs->weight_per_m2[e] == 0 : model.elements.inverse_mass[e] == 0) truth.weight_per_m2[e] = 0;
    const ResidualStats t = residual_stats(truth, change);
    summary["truth"] = {{"path", options.truth_path}, {"elements", t.elements}, {"rms_mm", t.rms_m * 1e3},
                        {"p95_mm", t.p95_m * 1e3}, {"max_mm", t.max_m * 1e3}, {"within_1mm", t.within_1mm}};
  }
  write_text_atomically(dir + "/summary.json", summary.dump(2) + "\n");
  if (options.plots)
    if (const std::string message = draw_fit_plot(dir); !message.empty()) std::fprintf(stderr, "voxbreast: %s\n", message.c_str());
  return summary;
}

namespace {

/// The truth of a synthetic observation: the scene's posture change with each tissue at its own
/// material's modulus (m, 3 per element).
std::vector<double> true_change_m(const Scene& scene, const ClContext& cl, const Lattice& lattice) {
  FitSpec fit = parse_fit_section(scene.source_text, scene.source_path);
  fit.regions = FitSpec::Regions::Labels;
  fit.tissues.clear();
  const FitRegions regions = make_fit_regions(fit, scene, lattice);
  const ForwardModel forward(scene, lattice, regions, fit, cl);
  return forward.solve(moduli_from_materials(scene, lattice, regions)).change_m();
}

double largest_displacement_m(const std::vector<double>& change) {
  double largest = 0;
  for (std::size_t k = 0; k + 2 < change.size(); k += 3)
    largest = std::max(largest, std::hypot(change[k], change[k + 1], change[k + 2]));
  return largest;
}

}  // namespace

double write_synthetic_labels(const Scene& scene, const ClContext& cl, const std::string& path, int subdivide) {
  const PreparedModel model = prepare_model(scene, &cl.info);
  const Lattice& lattice = model.lattice;
  const std::vector<double> change = true_change_m(scene, cl, lattice);
  std::vector<int> value_of_tissue(lattice.tissue_names.size());
  for (std::size_t t = 0; t < value_of_tissue.size(); ++t) {
    value_of_tissue[t] = int(t) + 1;  // shape models: the model_labels numbering
    for (const auto& [v, name] : scene.model.label_table)
      if (name == lattice.tissue_names[t]) {
        value_of_tissue[t] = v;  // the first input label value of the tissue
        break;
      }
  }
  const ImageVolume labels = deformed_label_map(lattice, change, value_of_tissue, subdivide);
  const int largest_value = *std::max_element(value_of_tissue.begin(), value_of_tissue.end());
  write_nifti(path, labels, largest_value < 256 ? NiftiType::UInt8 : NiftiType::Int16);
  return largest_displacement_m(change);
}

double write_synthetic_surface(const Scene& scene, const ClContext& cl, const std::string& path, int label_value) {
  const PreparedModel model = prepare_model(scene, &cl.info);
  const std::vector<SurfaceRegion> region = surface_regions(scene, model.lattice, {label_value}, "--surface-label");
  const std::vector<double> change = true_change_m(scene, cl, model.lattice);
  write_triangle_mesh_stl(path, deformed_boundary_mesh(model.lattice, change, region[0].tissue));
  return largest_displacement_m(change);
}

double write_synthetic_observation(const Scene& scene, const ClContext& cl, const std::string& path, double noise_m,
                                   std::uint64_t seed) {
  const PreparedModel model = prepare_model(scene, &cl.info);
  const Lattice& lattice = model.lattice;
  const std::vector<double> change = true_change_m(scene, cl, lattice);
  std::mt19937_64 random(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<float> field(3 * std::size_t(lattice.dims[0]) * lattice.dims[1] * lattice.dims[2], 0.0f);
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    const bool held = model.elements.inverse_mass[e] == 0;
    for (int a = 0; a < 3; ++a)
      field[3 * std::size_t(lattice.voxel_of_element[e]) + a] =
          float(change[3 * e + a] + (noise_m > 0 && !held ? noise_m * normal(random) : 0.0));
  }
  write_nifti_displacement(path, lattice_grid(lattice), field);
  return largest_displacement_m(change);
}

}  // namespace vb::app
