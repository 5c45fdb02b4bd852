#include "engine/bench/trade_study.hpp"

#include <algorithm>
#include <cmath>

#include "engine/bench/bench_knobs.hpp"
#include "engine/bench/field_error.hpp"
#include "engine/error.hpp"
#include "engine/sim/run.hpp"
#include "engine/sim/time_step.hpp"

namespace vb::bench {
namespace {

using Eigen::Vector3d;

std::vector<Vector3d> track_points(const Scene& s) {
  std::vector<Vector3d> points;
  for (const TrackSpec& t : s.tracks) points.push_back(t.point_m);
  return points;
}

}  // namespace

TradeStudy::Outcome TradeStudy::simulate(const BenchCase& c, std::int64_t max_steps, double max_time_s) const {
  const BenchScene& bs = scene(c.scene);
  const ClContext& cl = cl_;
  Outcome o;
  CaseResult& r = o.result;
  r.knobs = c;
  Scene s = bs.scene;
  apply_law(s, c.law);
  apply_integrator(s, c.integrator);
  s.solver.precision = c.precision;
  s.volume.preserve = c.volume;
  if (c.tolerance > 0) s.stop.equilibrium = c.tolerance;
  s.stop.max_steps = max_steps;
  s.stop.max_time_s = max_time_s;
  r.tolerance = s.stop.equilibrium;
  o.lattice = build_lattice(bs.volume, c.downsample);
  r.elements = o.lattice.element_count();
  r.spacing_m = o.lattice.spacing_m;
  try {
    o.elements = make_element_arrays(s, o.lattice);
    s.solver.dt_s.reset();
    r.auto_dt_s = choose_time_step(s, o.lattice, o.elements).dt_s;
    s.solver.dt_s = c.dt_factor * r.auto_dt_s;
    r.dt_s = *s.solver.dt_s;
    Simulator sim(s, o.lattice, o.elements, cl);
    r.device_bytes_per_element = double(sim.device_bytes()) / double(r.elements);
    // One step from rest and back, so that lazy kernel compilation is not timed.
    sim.advance(1);
    sim.check();
    sim.upload(o.elements.displacement_m, std::vector<double>(o.elements.displacement_m.size(), 0.0));
    const std::int64_t warm_up = sim.steps();
    RunOutput out = run_simulation(s, o.lattice, o.elements, sim);
    r.status = out.summary.converged ? "ok" : "not_converged";
    r.steps = out.summary.steps - warm_up;
    r.simulated_s = double(r.steps) * r.dt_s;
    r.wall_s = out.summary.wall_time_s;
    r.seconds_per_step = r.steps > 0 ? r.wall_s / double(r.steps) : 0;
    r.max_displacement_m = out.summary.max_displacement_m;
    r.volume_change = out.summary.surface_volume_change;
    o.u_m = std::move(out.state.displacement_m);
  } catch (const Error& e) {
    r.status = e.problem().find("went unstable") != std::string::npos ? "unstable" : "failed";
    r.message = e.what();
  } catch (const cl::Error& e) {
    r.status = "failed";
    r.message = std::string("OpenCL: ") + e.what() + " (" + cl_status_name(e.err()) + ")";
  }
  return o;
}

void TradeStudy::add_scene(BenchScene scene) {
  const std::string name = scene.name;
  scenes_[name] = std::move(scene);
}

void TradeStudy::expect(const BenchCase& c) {
  const double tol = c.tolerance > 0 ? c.tolerance : scene(c.scene).scene.stop.equilibrium;
  auto [it, added] = tightest_tolerance_.emplace(c.reference_key(), tol);
  if (!added) it->second = std::min(it->second, tol);
}

const BenchScene& TradeStudy::scene(const std::string& name) const {
  const auto it = scenes_.find(name);
  require(it != scenes_.end(), "no bench scene named '" + name + "'", "bench");
  return it->second;
}

void TradeStudy::measure(CaseResult& r, const Outcome& o, const Reference& ref) const {
  if (o.u_m.empty() || ref.u_m.empty()) return;
  const BenchScene& bs = scene(r.knobs.scene);
  const FieldError field = field_error(sample_displacement(o.lattice, o.u_m, ref.points_m), ref.u_m);
  r.error_max_m = field.max_m;
  r.error_rms_m = field.rms_m;
  if (!ref.track_u_m.empty()) {
    const auto tracked = sample_displacement(o.lattice, o.u_m, track_points(bs.scene));
    r.track_error_m = field_error(tracked, ref.track_u_m).max_m;
  }
  r.volume_error = std::abs(r.volume_change - ref.result.volume_change);
  if (bs.column) r.closed_form_error = -top_layer_mean_uz(o.lattice, o.u_m) / bs.column->sag_m() - 1;
}

const TradeStudy::Reference& TradeStudy::reference(const BenchCase& c, std::vector<CaseResult>& new_rows) {
  const std::string key = c.reference_key();
  if (const auto it = references_.find(key); it != references_.end()) return it->second;
  const BenchScene& bs = scene(c.scene);
  expect(c);
  const double tolerance = settings_.reference_tolerance_factor * tightest_tolerance_.at(key);
  const Outcome o = simulate(reference_case(c, settings_.reference_dt_factor, tolerance), settings_.reference_max_steps,
                             INFINITY);
  Reference ref;
  ref.result = o.result;
  if (!o.u_m.empty()) {
    for (std::size_t e = 0; e < o.lattice.element_count(); ++e) {
      if (o.elements.inverse_mass[e] == 0) continue;  // held: zero in every run, would dilute the RMS
      ref.points_m.push_back(o.lattice.rest_position(e));
      ref.u_m.emplace_back(o.u_m[3 * e], o.u_m[3 * e + 1], o.u_m[3 * e + 2]);
    }
    ref.track_u_m = sample_displacement(o.lattice, o.u_m, track_points(bs.scene));
  }
  measure(ref.result, o, ref);  // against itself: zero unless the sampling is wrong
  Reference& stored = references_[key] = std::move(ref);
  new_rows.push_back(stored.result);
  return stored;
}

std::vector<CaseResult> TradeStudy::run(const BenchCase& c) {
  std::vector<CaseResult> rows;
  const Reference& ref = reference(c, rows);
  if (c.part == "reference") {
    if (rows.empty()) rows.push_back(ref.result);
    return rows;
  }
  // A run that has not settled in several times the reference's simulated time will not.
  const double max_time = ref.result.status == "ok" ? settings_.max_time_over_reference * ref.result.simulated_s : INFINITY;
  const Outcome o = simulate(c, settings_.max_steps, max_time);
  CaseResult r = o.result;
  measure(r, o, ref);
  if (ref.u_m.empty() && r.message.empty()) r.message = "no error measure: the reference run is " + ref.result.status;
  rows.push_back(r);
  return rows;
}

}  // namespace vb::bench
