#include "engine/bench/bench_knobs.hpp"

#include <algorithm>

#include "engine/error.hpp"

namespace vb::bench {
namespace {

struct IntegratorSetting {
  const char* name;
  void (*apply)(SolverSpec&);
};

// One line per integrator or solver mode the bench can sweep.
const IntegratorSetting kIntegrators[] = {
    {"symplectic_euler", [](SolverSpec& s) { s.integrator = Integrator::SymplecticEuler; }},
    {"heun", [](SolverSpec& s) { s.integrator = Integrator::Heun; }},
    {"relaxation", [](SolverSpec& s) { s.integrator = Integrator::Relaxation, s.dt_safety = 0.9; }},
};

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace

std::vector<std::string> integrator_names() {
  std::vector<std::string> names;
  for (const IntegratorSetting& s : kIntegrators) names.emplace_back(s.name);
  return names;
}

void apply_integrator(Scene& scene, const std::string& name) {
  for (const IntegratorSetting& s : kIntegrators)
    if (name == s.name) return s.apply(scene.solver);
  throw Error("unknown integrator '" + name + "'", "bench", "use one of " + joined(integrator_names()));
}

std::vector<std::string> law_names() { return {"linear", "biphasic", "neo-hookean", "ogden"}; }

void apply_law(Scene& scene, const std::string& law) {
  const auto names = law_names();
  require(std::find(names.begin(), names.end(), law) != names.end(), "unknown law '" + law + "'", "bench",
          "use one of " + joined(names));
  for (auto& [tissue, m] : scene.materials) {
    if (m.rigid) continue;
    m.law = law;
    m.cubic = m.critical_strain = 0;
    m.ogden_mu_pa.clear();
    m.ogden_alpha.clear();
    if (law == "biphasic") {
      m.cubic = 20;
      m.critical_strain = 0.1;
    }
    if (law == "neo-hookean" || law == "ogden") m.poisson_ratio = 0.45;
    if (law == "ogden") {
      // μ₀ = ½ Σ μ_p α_p = ½ (1200·4 + 300·2) = 2700 Pa for the validation tissue
      const double scale = m.youngs_modulus_pa / (2 * (1 + m.poisson_ratio)) / 2700.0;
      m.ogden_mu_pa = {1200 * scale, -300 * scale};
      m.ogden_alpha = {4, -2};
    }
  }
}

const char* precision_name(Precision p) { return p == Precision::Double ? "double" : "float"; }

Precision parse_precision(const std::string& name) {
  if (name == "float") return Precision::Float;
  if (name == "double") return Precision::Double;
  throw Error("unknown precision '" + name + "'", "bench", "use float or double");
}

}  // namespace vb::bench
