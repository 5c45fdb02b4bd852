// voxbreast fit-curve SCENE.toml --curve measured.csv --out DIR — tunes one tissue's material
// parameters (biphasic E, cubic, critical_strain; one-term Ogden mu, alpha; E of linear and
// neo-Hookean tissue) so that the scene's quasi-static press gives the measured force curve
// (docs/FIT_CURVE.md). Writes fit_curve.json and fit_curve.csv.
//   voxbreast fit-curve data-samples/fit_curve/cube.toml --curve data-samples/fit_curve/measured.csv --out out/fit
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "apps/commands.hpp"
#include "apps/simulation_setup.hpp"
#include "engine/curve_fit/curve_fit.hpp"
#include "io/atomic_file.hpp"
#include "io/csv_table.hpp"
#include "io/numeric_csv.hpp"

namespace vb::app {
namespace {

struct FitCurveCliOptions {
  std::string scene, curve, out, device, precision, tissue;
  std::vector<std::string> params;
  int points = 12, max_evaluations = 120, probe = 1;
  bool quiet = false;
};

std::string fit_table_csv(const CurveFitResult& r) {
  std::string text = csv_line({"displacement_mm", "measured_n", "start_n", "fitted_n"});
  for (std::size_t k = 0; k < r.travel_m.size(); ++k)
    text += csv_line({shortest_number_text(1e3 * r.travel_m[k]), shortest_number_text(r.measured_n[k]),
                      shortest_number_text(r.start_n[k]), shortest_number_text(r.fitted_n[k])});
  return text;
}

nlohmann::json fit_json(const CurveFitResult& r) {
  nlohmann::json params = nlohmann::json::object();
  for (const FitValue& p : r.parameters) params[p.name] = {{"start", p.start}, {"fitted", p.fitted}};
  return {{"tissue", r.tissue},       {"law", r.law},
          {"parameters", params},     {"rms_n", r.rms_n},
          {"start_rms_n", r.start_rms_n}, {"relative_rms", r.relative_rms},
          {"max_error_n", r.max_error_n}, {"levels", r.travel_m.size()},
          {"evaluations", r.evaluations}, {"iterations", r.iterations},
          {"status", r.status}};
}

int run_fit_curve(const FitCurveCliOptions& o) {
  const Scene scene = load_scene(o.scene, o.precision);
  const ForceCurve curve = force_curve_from_rows(read_numeric_csv(o.curve, {"displacement_mm", "force_n"}), o.curve);
  const OutputDir output_dir(o.out);
  const ClContext cl(select_device(o.device));
  const PreparedModel model = prepare_model(scene, &cl.info);
  CurveFitOptions options;
  options.tissue = o.tissue;
  options.parameters = o.params;
  options.points = o.points;
  options.max_evaluations = o.max_evaluations;
  options.press.probe = std::size_t(o.probe - 1);
  if (!o.quiet)
    std::fprintf(stderr, "voxbreast: %zu elements, device %s; fitting a %zu-point curve up to %.3g mm\n",
                 model.lattice.element_count(), cl.info.name.c_str(), curve.travel_m.size(), 1e3 * curve.travel_m.back());
  const auto progress = [&](int n, double relative) {
    if (!o.quiet) std::fprintf(stderr, "  press curve %d: relative RMS %.3e\n", n, relative);
  };
  const CurveFitResult r = fit_force_curve(scene, model.lattice, cl, curve, options, progress);
  write_text_atomically(o.out + "/fit_curve.csv", fit_table_csv(r));
  write_text_atomically(o.out + "/fit_curve.json", fit_json(r).dump(2) + "\n");
  std::printf("%s (%d press curves, %d iterations)\n", r.status.c_str(), r.evaluations, r.iterations);
  for (const FitValue& p : r.parameters)
    std::printf("  %s.%s: %.6g -> %.6g\n", r.tissue.c_str(), p.name.c_str(), p.start, p.fitted);
  std::printf("fit error: RMS %.4g N (%.3g%% of the largest force; start %.4g N), max %.4g N\n", r.rms_n,
              100 * r.relative_rms, r.start_rms_n, r.max_error_n);
  std::printf("wrote %s/fit_curve.json\nwrote %s/fit_curve.csv\n", o.out.c_str(), o.out.c_str());
  return 0;
}

}  // namespace

Command add_fit_curve(CLI::App& app) {
  auto o = std::make_shared<FitCurveCliOptions>();
  auto* sub = app.add_subcommand("fit-curve", "Tune a tissue's material parameters to a measured force-displacement "
                                              "curve of the scene's press (fit_curve.json, fit_curve.csv)");
  sub->add_option("scene", o->scene, "scene file (TOML) with the model, its anchors and a pressing [[indenter]]")
      ->required()->check(CLI::ExistingFile);
  sub->add_option("--curve,-c", o->curve, "measured curve: CSV displacement_mm,force_n")->required();
  sub->add_option("--out,-o", o->out, "output folder")->required();
  sub->add_option("--tissue", o->tissue, "tissue whose material is fitted (default: the only one)");
  sub->add_option("--params", o->params, "parameters: E, cubic, critical_strain, mu, alpha (default: the law's)")
      ->delimiter(',');
  sub->add_option("--points", o->points, "press levels compared, evenly over the travel (0: every measured one)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  sub->add_option("--max-evaluations", o->max_evaluations, "press curves at most")
      ->capture_default_str()->check(CLI::PositiveNumber);
  sub->add_option("--probe", o->probe, "which [[indenter]] presses (from 1)")->check(CLI::PositiveNumber);
  sub->add_option("--device,-d", o->device, "OpenCL device: gpu, cpu, an index or a name");
  sub->add_option("--precision", o->precision, "override solver.precision")->check(CLI::IsMember({"float", "double"}));
  sub->add_flag("--quiet,-q", o->quiet, "no progress lines");
  return {sub, [o] { return run_fit_curve(*o); }};
}

}  // namespace vb::app
