#include "engine/bench/bench_design.hpp"

#include <set>
#include <sstream>

#include "engine/bench/bench_knobs.hpp"

namespace vb::bench {

std::string BenchCase::knobs() const {
  std::ostringstream s;
  s << scene << " " << law << " " << integrator << " " << precision_name(precision) << " d" << downsample << " dt*"
    << dt_factor << (volume ? " volume" : "");
  if (tolerance > 0) s << " tol " << tolerance;
  return s.str();
}

std::string BenchCase::reference_key() const { return scene + " " + law + (volume ? " volume" : ""); }

std::vector<BenchCase> make_design(const std::string& scene, const DesignSpec& spec) {
  std::vector<BenchCase> cases;
  std::set<std::string> seen;
  const auto add = [&](BenchCase c, const std::string& part) {
    c.scene = scene;
    c.part = part;
    if (seen.insert(c.knobs()).second) cases.push_back(c);
  };
  const int base_resolution = spec.downsamples.empty() ? 1 : spec.downsamples.front();
  for (const std::string& law : spec.base_laws) {
    BenchCase base;
    base.law = law;
    base.integrator = spec.base_integrator;
    base.precision = spec.base_precision;
    base.downsample = base_resolution;
    add(base, "base");
  }
  for (const std::string& law : spec.laws)
    for (const std::string& integrator : spec.integrators)
      for (Precision p : spec.precisions) {
        BenchCase c;
        c.law = law;
        c.integrator = integrator;
        c.precision = p;
        c.downsample = base_resolution;
        add(c, "grid");
      }
  for (const std::string& law : spec.base_laws) {
    BenchCase base;
    base.law = law;
    base.integrator = spec.base_integrator;
    base.precision = spec.base_precision;
    base.downsample = base_resolution;
    for (int d : spec.downsamples) {
      BenchCase c = base;
      c.downsample = d;
      add(c, "resolution");
    }
    for (double f : spec.dt_factors) {
      BenchCase c = base;
      c.dt_factor = f;
      add(c, "time_step");
    }
    if (spec.volume) {
      BenchCase c = base;
      c.volume = true;
      add(c, "volume");
    }
    for (double tol : spec.tolerances)
      for (Precision p : spec.precisions) {
        BenchCase c = base;
        c.precision = p;
        c.tolerance = tol;
        add(c, "tolerance");
      }
  }
  return cases;
}

BenchCase reference_case(const BenchCase& c, double dt_factor, double tolerance) {
  BenchCase r = c;
  r.tolerance = tolerance;
  r.integrator = "heun";
  r.precision = Precision::Double;
  r.downsample = 1;
  r.dt_factor = dt_factor;
  r.part = "reference";
  return r;
}

}  // namespace vb::bench
