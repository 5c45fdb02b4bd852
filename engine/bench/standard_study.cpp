#include "engine/bench/standard_study.hpp"

#include <algorithm>

#include "engine/bench/bench_knobs.hpp"
#include "engine/error.hpp"

namespace vb::bench {
namespace {

bool wanted(const std::vector<std::string>& only, const std::string& name) {
  return only.empty() || std::find(only.begin(), only.end(), name) != only.end();
}

std::vector<std::string> filtered(const std::vector<std::string>& all, const std::vector<std::string>& only) {
  std::vector<std::string> out;
  for (const std::string& n : all)
    if (wanted(only, n)) out.push_back(n);
  return out;
}

void check_names(const std::vector<std::string>& given, const std::vector<std::string>& known, const std::string& what) {
  for (const std::string& n : given)
    require(wanted(known, n), "unknown " + what + " '" + n + "'", "bench --" + what + "s");
}

}  // namespace

std::vector<std::string> standard_scene_names() { return {"column", "phantom", "phantom_large"}; }

StudyPlan standard_plan(const PlanOptions& o) {
  check_names(o.scenes, standard_scene_names(), "scene");
  check_names(o.laws, law_names(), "law");
  check_names(o.integrators, integrator_names(), "integrator");
  // --quick leaves the Ogden law out of the grid by default (its PoCL reference alone takes a minute)
  const std::vector<std::string> laws =
      filtered(law_names(), !o.laws.empty() ? o.laws : o.quick ? std::vector<std::string>{"linear", "biphasic", "neo-hookean"}
                                                                : std::vector<std::string>{});
  const std::vector<std::string> integrators = filtered(integrator_names(), o.integrators);
  require(!laws.empty() && !integrators.empty(), "no law or no integrator left to run", "bench");
  const auto base_laws = [&](std::vector<std::string> preferred) {
    std::vector<std::string> out = filtered(preferred, laws);
    return out.empty() ? std::vector<std::string>{laws.front()} : out;
  };
  const auto base_integrator = [&] { return wanted(integrators, "heun") ? std::string("heun") : integrators.front(); };

  StudyPlan plan;
  const auto add = [&](BenchScene scene, const DesignSpec& spec) {
    for (BenchCase& c : make_design(scene.name, spec)) plan.cases.push_back(c);
    plan.scenes.push_back(std::move(scene));
  };

  DesignSpec spec;
  spec.laws = laws;
  spec.integrators = integrators;
  spec.precisions = {Precision::Float, Precision::Double};
  spec.base_integrator = base_integrator();
  spec.base_laws = base_laws(o.quick ? std::vector<std::string>{"linear"} : std::vector<std::string>{"linear", "neo-hookean"});
  spec.downsamples = {1, 2, 4};
  spec.dt_factors = {0.5, 1, 2, 4};  // ×4 is past the springs' stability limit: shows how it is reported
  // Tighter than float's round-off floor (docs/VALIDATION.md): where double pays off.
  spec.tolerances = o.quick ? std::vector<double>{1e-9} : std::vector<double>{1e-7, 1e-9};

  // Column: 2 × 2 × 5 cm free, 2.5 mm (quick) or 1.25 mm voxels at the finest resolution.
  if (wanted(o.scenes, "column")) add(o.quick ? column_scene(8, 20, 0.0025) : column_scene(16, 40, 0.00125), spec);

  if (!o.phantom_scene.empty() && wanted(o.scenes, "phantom")) {
    DesignSpec p = spec;
    if (o.quick) {  // 8 mm lattice (2,231 elements) and 16 mm; linear springs unless --laws asks
      p.laws = o.laws.empty() ? base_laws({"linear"}) : laws;
      p.base_laws = base_laws({"linear"});
      p.downsamples = {1, 2};
      p.dt_factors = {0.5, 1, 2};
    }
    add(image_scene("phantom", o.phantom_scene, o.quick ? 0.008 : 0), p);
  }
  if (!o.phantom_scene.empty() && o.large && wanted(o.scenes, "phantom_large")) {
    // Each run is ~1.5M elements: linear springs only unless --laws asks (a hyperelastic reference
    // alone would take minutes on an H200), so that the whole GPU study fits one 10-minute call.
    DesignSpec p = spec;
    p.laws = o.laws.empty() ? base_laws({"linear"}) : laws;
    p.base_laws = base_laws({"linear"});
    p.dt_factors = {0.5, 1, 2};
    add(image_scene("phantom_large", o.phantom_scene, kLargePhantomSpacing), p);
  }
  require(!plan.cases.empty(), "the bench has nothing to run", "bench --scenes",
          "the phantom scenes need --phantom (the scene.toml of `voxbreast phantom`)");
  return plan;
}

}  // namespace vb::bench
