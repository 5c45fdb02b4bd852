#include "io/fit_file.hpp"

#include <algorithm>
#include <filesystem>

#include "engine/error.hpp"
#include "engine/loads/posture.hpp"
#include "io/did_you_mean.hpp"
#include "io/toml_text.hpp"

namespace vb {
namespace {

const std::vector<std::string_view> kKeys = {
    "from_posture", "from_gravity", "dvf", "landmarks", "mask", "sigma", "sigma_mm", "regions", "block_mm",
    "tissues", "min_E", "max_E", "initial", "method", "max_iterations", "regularisation", "step_log",
    "tolerance", "equilibrium", "max_steps", "batch", "observed_labels", "observed_label_values",
    "observed_surface", "observed_surface_values", "unloaded_reference"};

class FitTable {
 public:
  FitTable(const toml::table& t, std::string source) : t_(t), source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what, const std::string& hint = {}) const {
    const toml::node* n = t_.get(key);
    const int line = int((n ? n->source() : t_.source()).begin.line);
    throw Error(what, source_ + ":" + std::to_string(line) + " key 'fit." + key + "'", hint);
  }
  std::optional<std::string> text(const std::string& key) const {
    const toml::node* n = t_.get(key);
    if (!n) return std::nullopt;
    if (!n->is_string()) fail(key, "expected a string");
    return n->as_string()->get();
  }
  std::optional<double> number(const std::string& key, double min, bool open) const {
    const toml::node* n = t_.get(key);
    if (!n) return std::nullopt;
    const std::optional<double> v = n->value<double>();
    if (!v || (n->type() != toml::node_type::floating_point && n->type() != toml::node_type::integer))
      fail(key, "expected a number");
    if (open ? !(*v > min) : !(*v >= min))
      fail(key, "must be " + std::string(open ? "> " : ">= ") + std::to_string(min));
    return v;
  }
  std::optional<Vec3> vec3(const std::string& key) const {
    const toml::node* n = t_.get(key);
    if (!n) return std::nullopt;
    const toml::array* a = n->as_array();
    if (!a || a->size() != 3) fail(key, "expected an array of 3 numbers");
    Vec3 v;
    for (int i = 0; i < 3; ++i) {
      const std::optional<double> x = (*a)[i].value<double>();
      if (!x) fail(key, "expected an array of 3 numbers");
      v[i] = *x;
    }
    return v;
  }
  std::optional<std::vector<std::string>> strings(const std::string& key) const {
    const toml::node* n = t_.get(key);
    if (!n) return std::nullopt;
    const toml::array* a = n->as_array();
    if (!a) fail(key, "expected an array of strings");
    std::vector<std::string> out;
    for (const toml::node& x : *a) {
      if (!x.is_string()) fail(key, "expected an array of strings");
      out.push_back(x.as_string()->get());
    }
    return out;
  }
  template <typename E>
  std::optional<E> choice(const std::string& key, const std::vector<std::pair<std::string, E>>& names) const {
    const std::optional<std::string> v = text(key);
    if (!v) return std::nullopt;
    std::vector<std::string_view> accepted;
    for (const auto& [name, value] : names) {
      if (name == *v) return value;
      accepted.push_back(name);
    }
    std::string hint = did_you_mean(*v, accepted);
    fail(key, "unknown value '" + *v + "'", hint.empty() ? "one of the accepted values" : hint);
  }
  void check_keys() const {
    for (const auto& [key, node] : t_) {
      const std::string k(key.str());
      if (std::find(kKeys.begin(), kKeys.end(), k) != kKeys.end()) continue;
      std::string hint = did_you_mean(k, kKeys);
      fail(k, "unknown key", hint.empty() ? "see docs/FIT.md for the [fit] keys" : hint);
    }
  }
  std::optional<std::vector<int>> integers(const std::string& key, int min) const {
    const toml::node* n = t_.get(key);
    if (!n) return std::nullopt;
    const toml::array* a = n->as_array();
    if (!a || a->empty()) fail(key, "expected a non-empty array of integers");
    std::vector<int> out;
    for (const toml::node& x : *a) {
      const std::optional<std::int64_t> v = x.value<std::int64_t>();
      if (!x.is_integer() || !v) fail(key, "expected a non-empty array of integers");
      if (*v < min || *v > 65535) fail(key, "values must lie in [" + std::to_string(min) + ", 65535]");
      out.push_back(int(*v));
    }
    return out;
  }
  std::optional<bool> boolean(const std::string& key) const {
    const toml::node* n = t_.get(key);
    if (!n) return std::nullopt;
    if (!n->is_boolean()) fail(key, "expected true or false");
    return n->as_boolean()->get();
  }
  int line() const { return int(t_.source().begin.line); }

 private:
  const toml::table& t_;
  std::string source_;
};

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
  const FitTable t(*table, scene_path);
  t.check_keys();
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
  if (table->get("observed_surface")) {  // one STL, or several (one per boundary)
    if (const auto one = table->get("observed_surface")->as_string()) f.observed_surface_paths = {one->get()};
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
  if (const auto v = t.integers("observed_surface_values", 0)) {
    if (f.observed_surface_paths.empty()) t.fail("observed_surface_values", "applies only with 'observed_surface'");
    f.observed_surface_values = *v;
  } else if (f.observed_surface_paths.size() == 1) {
    f.observed_surface_values = {0};  // one surface: the body outline
  }
  if (f.observed_surface_values.size() != f.observed_surface_paths.size())
    t.fail("observed_surface_values", "give one value per surface in 'observed_surface' (0: the body outline, "
                                      "v: the boundary of the region of label v)");
  if (const auto v = t.integers("observed_label_values", 0)) {
    if (f.observed_labels_path.empty()) t.fail("observed_label_values", "applies only with 'observed_labels'");
    f.observed_label_values = *v;
  }
  f.unloaded_reference = t.boolean("unloaded_reference");
  if (const auto s = t.number("sigma_mm", 0, true)) f.sigma_m = *s * 1e-3;
  using R = FitSpec::Regions;
  f.regions = t.choice<R>("regions", {{"labels", R::Labels}, {"blocks", R::Blocks}, {"elements", R::Elements}})
                  .value_or(f.regions);
  if (const auto b = t.number("block_mm", 0, true)) {
    if (f.regions != R::Blocks) t.fail("block_mm", "applies only with regions = \"blocks\"");
    f.block_m = *b * 1e-3;
  }
  f.tissues = t.strings("tissues").value_or(f.tissues);
  f.min_modulus_pa = t.number("min_E", 0, true).value_or(0);
  f.max_modulus_pa = t.number("max_E", 0, true).value_or(0);
  if (f.min_modulus_pa > 0 && f.max_modulus_pa > 0 && f.max_modulus_pa <= f.min_modulus_pa)
    t.fail("max_E", "must be larger than min_E");
  using I = FitSpec::Initial;
  f.initial = t.choice<I>("initial", {{"hu", I::Hu}, {"materials", I::Materials}}).value_or(f.initial);
  using M = FitSpec::Method;
  f.method = t.choice<M>("method", {{"gauss-newton", M::GaussNewton}, {"bisection", M::Bisection}}).value_or(f.method);
  if (const auto n = t.number("max_iterations", 0, false)) f.max_iterations = int(*n);
  f.regularisation = t.number("regularisation", 0, false).value_or(f.regularisation);
  f.step_log = t.number("step_log", 0, true).value_or(f.step_log);
  f.tolerance = t.number("tolerance", 0, false).value_or(f.tolerance);
  f.equilibrium = t.number("equilibrium", 0, true).value_or(f.equilibrium);
  if (const auto n = t.number("max_steps", 1, false)) f.max_steps = std::int64_t(*n);
  if (const toml::node* n = table->get("batch")) {
    if (n->is_string() && n->as_string()->get() == "auto") f.batch = 0;
    else if (!n->is_integer() || n->as_integer()->get() < 0 || n->as_integer()->get() > 256)
      t.fail("batch", "expected \"auto\" or an integer from 0 (auto) to 256", "batch = 1 solves one copy at a time");
    else f.batch = int(n->as_integer()->get());
  }
  return f;
}

}  // namespace vb
