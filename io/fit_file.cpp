#include "io/fit_file.hpp"

#include <algorithm>
#include <filesystem>

#include "engine/error.hpp"
#include "engine/loads/posture.hpp"
#include "io/toml_section.hpp"
#include "io/toml_text.hpp"

namespace vb {
using namespace scene_toml;
namespace {

const Keys kKeys = {
    "from_posture", "from_gravity", "dvf", "landmarks", "mask", "sigma", "sigma_mm", "regions", "block_mm",
    "tissues", "min_E", "max_E", "initial", "method", "max_iterations", "regularisation", "step_log",
    "tolerance", "equilibrium", "max_steps", "batch", "observed_labels", "observed_label_values",
    "observed_surface", "observed_surface_values", "unloaded_reference"};

/// Observed label values: a non-empty array of integers in [0, 65535] (0: the body outline).
std::optional<std::vector<int>> label_values(const Section& t, std::string_view key) {
  const toml::node* n = t.find(key);
  if (!n) return std::nullopt;
  const toml::array* a = n->as_array();
  const auto is_integer = [](const toml::node& x) { return x.is_integer(); };
  if (!a || a->empty() || !std::all_of(a->begin(), a->end(), is_integer))
    t.fail(key, "expected a non-empty array of integers, got " + describe(*n));
  std::vector<int> out;
  for (const toml::node& x : *a) {
    const std::int64_t v = x.as_integer()->get();
    if (v < 0 || v > 65535) t.fail(key, "values must lie in [0, 65535]");
    out.push_back(int(v));
  }
  return out;
}

std::string resolved(const std::string& path, const std::string& scene_path) {
  if (path.empty() || std::filesystem::path(path).is_absolute()) return path;
  return (std::filesystem::path(scene_path).parent_path() / path).lexically_normal().string();
}

}  // namespace

FitSpec parse_fit_section(const std::string& scene_text, const std::string& scene_path) {
  const toml::table root = parse_toml_text(scene_text, scene_path);
  const toml::table* table = root["fit"].as_table();
  require(table != nullptr, "the scene has no [fit] table", scene_path,
          "add [fit] with the observation (dvf or landmarks): docs/FIT.md");
  const Section t(*table, "fit", scene_path);
  t.check_keys(kKeys);
  FitSpec f;
  f.line = t.line();
  const std::optional<Vec3> g = t.vec3("from_gravity");
  const std::optional<std::string> posture = t.text("from_posture");
  if (g && posture) t.fail("from_gravity", "give either 'from_gravity' or 'from_posture', not both");
  if (g) f.from_gravity_m_s2 = *g;
  if (posture && *posture != "none") {
    try {
      f.from_gravity_m_s2 = gravity_for_posture(*posture);
    } catch (const Error& e) {
      t.fail("from_posture", e.problem(), "\"none\" or " + e.hint());
    }
    f.from_posture = *posture;
  }
  f.dvf_path = resolved(t.text("dvf").value_or(""), scene_path);
  f.landmarks_path = resolved(t.text("landmarks").value_or(""), scene_path);
  f.mask_path = resolved(t.text("mask").value_or(""), scene_path);
  f.sigma_path = resolved(t.text("sigma").value_or(""), scene_path);
  f.observed_labels_path = resolved(t.text("observed_labels").value_or(""), scene_path);
  if (const toml::node* surface = t.find("observed_surface")) {  // one STL, or several (one per boundary)
    if (const auto one = surface->as_string()) f.observed_surface_paths = {one->get()};
    else f.observed_surface_paths = t.strings("observed_surface").value_or(std::vector<std::string>{});
    if (f.observed_surface_paths.empty()) t.fail("observed_surface", "expected an STL file or an array of them");
    for (std::string& p : f.observed_surface_paths) p = resolved(p, scene_path);
  }
  const int kinds = int(!(f.dvf_path.empty() && f.landmarks_path.empty())) + int(!f.observed_labels_path.empty()) +
                    int(!f.observed_surface_paths.empty());
  if (kinds == 0)
    t.fail("dvf", "[fit] needs an observation: 'dvf' (NIfTI displacement field), 'landmarks' (CSV), "
                  "'observed_labels' (label map of the observed posture) or 'observed_surface' (STL)");
  if (kinds > 1)
    t.fail(f.observed_surface_paths.empty() ? "observed_labels" : "observed_surface",
           "give one kind of observation: displacements ('dvf', 'landmarks'), 'observed_labels' or 'observed_surface'");
  if (const auto v = label_values(t, "observed_surface_values")) {
    if (f.observed_surface_paths.empty()) t.fail("observed_surface_values", "applies only with 'observed_surface'");
    f.observed_surface_values = *v;
  } else if (f.observed_surface_paths.size() == 1) {
    f.observed_surface_values = {0};  // one surface: the body outline
  }
  if (f.observed_surface_values.size() != f.observed_surface_paths.size())
    t.fail("observed_surface_values", "give one value per surface in 'observed_surface' (0: the body outline, "
                                      "v: the boundary of the region of label v)");
  if (const auto v = label_values(t, "observed_label_values")) {
    if (f.observed_labels_path.empty()) t.fail("observed_label_values", "applies only with 'observed_labels'");
    f.observed_label_values = *v;
  }
  f.unloaded_reference = t.boolean("unloaded_reference");
  if (const auto s = t.positive("sigma_mm")) f.sigma_m = *s * 1e-3;
  using R = FitSpec::Regions;
  static const NameTable<R> kRegions = {{"labels", R::Labels, {}}, {"blocks", R::Blocks, {}}, {"elements", R::Elements, {}}};
  if (const auto* r = t.named("regions", kRegions)) f.regions = r->value;
  if (const auto b = t.positive("block_mm")) {
    if (f.regions != R::Blocks) t.fail("block_mm", "applies only with regions = \"blocks\"");
    f.block_m = *b * 1e-3;
  }
  f.tissues = t.strings("tissues").value_or(f.tissues);
  f.min_modulus_pa = t.positive("min_E").value_or(0);
  f.max_modulus_pa = t.positive("max_E").value_or(0);
  if (f.min_modulus_pa > 0 && f.max_modulus_pa > 0 && f.max_modulus_pa <= f.min_modulus_pa)
    t.fail("max_E", "must be larger than min_E");
  using I = FitSpec::Initial;
  static const NameTable<I> kInitial = {{"hu", I::Hu, {}}, {"materials", I::Materials, {}}};
  if (const auto* i = t.named("initial", kInitial)) f.initial = i->value;
  using M = FitSpec::Method;
  static const NameTable<M> kMethods = {{"gauss-newton", M::GaussNewton, {}}, {"bisection", M::Bisection, {}}};
  if (const auto* m = t.named("method", kMethods)) f.method = m->value;
  f.max_iterations = t.integer<int>("max_iterations", 0).value_or(f.max_iterations);
  f.regularisation = t.non_negative("regularisation").value_or(f.regularisation);
  f.step_log = t.positive("step_log").value_or(f.step_log);
  f.tolerance = t.non_negative("tolerance").value_or(f.tolerance);
  f.equilibrium = t.positive("equilibrium").value_or(f.equilibrium);
  f.max_steps = t.integer<std::int64_t>("max_steps", 1).value_or(f.max_steps);
  if (const toml::node* n = t.find("batch")) {
    if (n->is_string() && n->as_string()->get() == "auto") f.batch = 0;
    else if (!n->is_integer() || n->as_integer()->get() < 0 || n->as_integer()->get() > 256)
      t.fail("batch", "expected \"auto\" or an integer from 0 (auto) to 256", "batch = 1 solves one copy at a time");
    else f.batch = int(n->as_integer()->get());
  }
  return f;
}

}  // namespace vb
