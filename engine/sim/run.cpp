#include "engine/sim/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "engine/device/torus.hpp"
#include "engine/error.hpp"
#include "engine/sim/instability.hpp"
#include "engine/results/element_measures.hpp"
#include "engine/sim/element_mass.hpp"
#include "engine/sim/contact_checks.hpp"
#include "engine/surface/enclosed_volume.hpp"

namespace vb {
namespace {

const char* integrator_name(Integrator i) {
  return i == Integrator::Heun ? "heun" : i == Integrator::Relaxation ? "relaxation" : "symplectic_euler";
}

/// Throws when a hyperelastic element ends the run inverted or crushed (det F ≤ 0, from the host
/// fit of element_measures): such a state is not a result, whatever the residual says.
void require_no_inverted_element(const Lattice& lattice, const ElementArrays& el, const FinalState& st) {
  // The kernels' law id per tissue: 1 and 2 are the hyperelastic laws (rigid tissue is 0).
  const auto hyperelastic = [&](std::size_t e) {
    const double law = el.material_table.empty() ? 0 : el.material_table[lattice.tissue_of_element[e]][0];
    return law == 1 || law == 2;
  };
  std::size_t inverted = 0, worst = 0;
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    if (!hyperelastic(e) || st.volumetric_strain[e] > -1) continue;
    if (inverted++ == 0 || st.volumetric_strain[e] < st.volumetric_strain[worst]) worst = e;
  }
  if (inverted == 0) return;
  std::ostringstream msg;
  msg << inverted << " hyperelastic element" << (inverted > 1 ? "s end" : " ends")
      << " the run inverted or crushed (det F <= 0), the worst " << element_name(lattice, worst)
      << " with det F = " << 1 + st.volumetric_strain[worst];
  throw Error(msg.str(), "solver",
              "the result is not physical; check what pushed it through its neighbours (anchors, indenter travel) "
              "or use a smaller solver.dt");
}

/// Device contact at a check: the latest values, and the deepest penetration so far.
void record_tori(const Scene& scene, double t_s, const StateCheck& c, std::vector<TorusResult>& out) {
  out.resize(scene.tori.size());
  for (std::size_t i = 0; i < scene.tori.size(); ++i) {
    TorusResult& r = out[i];
    const TorusContactCheck& k = c.tori[i];
    const TorusRadii radii = torus_radii(scene.tori[i], t_s);
    r.name = scene.tori[i].name;
    r.minor_radius_m = radii.minor_m;
    r.major_radius_m = radii.major_m;
    r.force_n = k.force_n;
    r.contact_elements = k.contact_elements;
    r.contact_area_m2 = k.contact_area_m2;
    r.normal_force_sum_n = k.normal_force_sum_n;
    r.mean_pressure_pa = k.contact_area_m2 > 0 ? k.normal_force_sum_n / k.contact_area_m2 : 0;
    r.peak_pressure_pa = k.peak_pressure_pa;
    r.max_penetration_m = k.max_penetration_m;
    r.max_penetration_run_m = std::max(r.max_penetration_run_m, k.max_penetration_m);
  }
}

/// The largest gravity load on a free element at rest over its own tissue's E·h²: the residual
/// ratio of the undeformed model under gravity alone (0 without gravity).
double gravity_load_ratio(const Scene& scene, const Lattice& lattice, const ElementArrays& el) {
  if (!scene.gravity.active) return 0;
  const double g = scene.gravity.acceleration_m_s2.norm(), h = lattice.spacing_m;
  double ratio = 0;
  for (std::size_t e = 0; e < el.mass_kg.size(); ++e)
    if (el.inverse_mass[e] != 0 && el.youngs_modulus_pa[e] > 0)
      ratio = std::max(ratio, el.mass_kg[e] * g / (el.youngs_modulus_pa[e] * h * h));
  return ratio;
}

/// Why a run with an equilibrium test has no converged result, or "" when it has one.
std::string unconverged_reason(const Scene& scene, const Lattice& lattice, const ElementArrays& el,
                               const Simulator& sim, const RunSummary& s, std::int64_t check_every) {
  const double tol = scene.stop.equilibrium;
  char text[512];
  if (!s.converged) {
    const char* limit = s.stop_reason == "max_time" ? "stop.time" : "stop.max_steps";
    std::snprintf(text, sizeof text,
                  "stopped at %s after %lld steps before equilibrium: residual %.2g and speed %.2g of the "
                  "tolerance's scales, tolerance stop.equilibrium = %.2g",
                  limit, (long long)sim.steps(), s.final_residual, s.final_speed_ratio, tol);
    return text;
  }
  // Met at the first check with only gravity loading the model, whose load at rest is within the
  // tolerance: the test could not tell the deformed state from the undeformed one.
  const double load = gravity_load_ratio(scene, lattice, el);
  if (sim.steps() <= check_every && scene.indenters.empty() && scene.tori.empty() && load > 0 && load <= tol) {
    std::snprintf(text, sizeof text,
                  "equilibrium met trivially at the first check: gravity's load on an element at rest is at most "
                  "%.2g of its tissue's E*h^2, within stop.equilibrium = %.2g, so the test cannot tell the result "
                  "from the undeformed model; set stop.equilibrium well below %.2g",
                  load, tol, load);
    return text;
  }
  return "";
}

}  // namespace

EquilibriumScales equilibrium_scales(const Lattice& lattice, const ElementArrays& el) {
  // Over the free elements: held tissue (rigid bone at 1 GPa, say) must not loosen the criterion.
  // The wave speed from the density (a voxel's mass): a hyperelastic surface element's mass is
  // its share of the body, not a lighter material.
  double E_max = 0, m_min = INFINITY;
  for (std::size_t e = 0; e < el.mass_kg.size(); ++e) {
    if (el.inverse_mass[e] == 0) continue;
    E_max = std::max(E_max, el.youngs_modulus_pa[e]);
    m_min = std::min(m_min, el.mass_kg[e] / mass_volume_fraction(lattice, el, e));
  }
  const double h = lattice.spacing_m;
  return {E_max * h * h, std::sqrt(E_max / (m_min / (h * h * h))),
          h * Eigen::Vector3d(lattice.dims[0], lattice.dims[1], lattice.dims[2]).norm()};
}

bool at_equilibrium(const Simulator& sim, const StateCheck& c, const EquilibriumScales& scales, double tol) {
  if (!(c.residual_ratio <= tol)) return false;
  // A dynamic run's speed test bounds a like distance, tol·c / ω_min. The residual alone let
  // relaxation stop 1% of the displacement from equilibrium on a soft column at 1e-5
  // (docs/BENCHMARKS.md).
  if (sim.relaxing()) return c.max_speed_m_s / std::sqrt(sim.relaxation_omega_sq()) <= tol * scales.size_m;
  return c.speed_ratio <= tol;
}

std::optional<std::string> float_floor_hint(const Scene& scene, const RunSummary& s) {
  // Float resolves a residual to ~4e-7 of F_ref (docs/VALIDATION.md, "Float equilibrium floor"),
  // so a tolerance within a few times of it is where round-off, not dynamics, can hold a run.
  constexpr double kFloatFloorTolerance = 3e-6;
  const double tol = scene.stop.equilibrium;
  if (s.converged || s.stop_reason != "max_steps" || scene.solver.precision != Precision::Float ||
      scene.solver.integrator == Integrator::Relaxation || !(tol > 0) || tol > kFloatFloorTolerance ||
      s.final_residual > tol || !(s.final_speed_ratio > tol))
    return std::nullopt;
  char text[320];
  std::snprintf(text, sizeof text,
                "stopped at stop.max_steps with its residual met (%.2g) but its speed at %.2g of the wave speed "
                "(tolerance %.2g): float's round-off can keep speeds above it; set solver.precision = "
                "\"double\", loosen stop.equilibrium, or use solver.integrator = \"relaxation\"",
                s.final_residual, s.final_speed_ratio, tol);
  return std::string(text);
}

std::size_t nearest_element(const Lattice& lattice, const Vec3& p) {
  std::size_t best = 0;
  double best_d2 = INFINITY;
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    const double d2 = (lattice.rest_position(e) - p).squaredNorm();
    if (d2 < best_d2) best_d2 = d2, best = e;
  }
  return best;
}

RunOutput run_simulation(const Scene& scene, const Lattice& lattice, const ElementArrays& el, Simulator& sim,
                         const std::function<void(const RunProgress&)>& progress, bool refuse_penetrating_start) {
  require_anchored(scene, lattice, el);  // a free part under gravity never settles
  const auto start = std::chrono::steady_clock::now();
  const EquilibriumScales scales = equilibrium_scales(lattice, el);
  const double h = lattice.spacing_m, extent = scales.size_m;
  const double tol = scene.stop.equilibrium;
  double travel_end = 0;  // equilibrium only counts once every moving indenter has stopped
  for (const IndenterSpec& ind : scene.indenters) {
    if (ind.velocity_m_s.squaredNorm() > 0) travel_end = std::max(travel_end, ind.travel_time_s);
    if (!ind.path.empty()) travel_end = std::max(travel_end, ind.path.back().time_s);
  }
  for (const TorusSpec& t : scene.tori) travel_end = std::max(travel_end, torus_inflation_end_s(t));
  check_contact_before_run(scene, lattice, el, sim, refuse_penetrating_start);
  const std::int64_t check_every = std::max(1, scene.solver.check_every);
  const std::int64_t frames_every = scene.output.frames_every;
  std::int64_t max_steps = scene.stop.max_steps;
  if (std::isfinite(scene.stop.max_time_s)) {
    const double steps_in_time = scene.stop.max_time_s / sim.dt_s();
    require(steps_in_time >= 1 - 1e-9,
            "stop.time = " + number_text(scene.stop.max_time_s) + " s is shorter than one step (dt = " +
                number_text(sim.dt_s()) + " s), so the run would take no step",
            "stop.time", "give a time of at least one step, or leave it out");
    max_steps = std::min<std::int64_t>(max_steps, std::int64_t(std::min(std::ceil(steps_in_time - 1e-9), 9e18)));
  }

  RunOutput out;
  RunSummary& s = out.summary;
  StateCheck c;
  s.stop_reason = "max_steps";
  for (;;) {
    std::int64_t chunk = std::min(check_every, max_steps - sim.steps());
    if (frames_every > 0) chunk = std::min(chunk, frames_every - sim.steps() % frames_every);
    sim.advance(chunk);
    c = sim.check();
    if (c.nonfinite_elements > 0)
      report_instability(scene, lattice, el, sim, c,
                         std::to_string(c.nonfinite_elements) + " of " + std::to_string(lattice.element_count()) +
                             " elements have non-finite state",
                         ", the first being ");
    if (c.max_speed_m_s * sim.dt_s() > 0.5 * h)
      report_instability(scene, lattice, el, sim, c, "an element moves more than half a spacing per step", " at ");
    if (c.max_displacement_m > 10 * extent)
      report_instability(scene, lattice, el, sim, c, "displacement exceeds ten times the model size", " at ");

    s.final_residual = c.residual_ratio;
    s.final_speed_ratio = c.speed_ratio;
    if (frames_every > 0 && sim.steps() % frames_every == 0) {
      std::vector<double> u, v;
      sim.download(u, v);
      out.frames.time_s.push_back(sim.time_s());
      out.frames.displacement_m.emplace_back(u.begin(), u.end());
    }
    s.indenters.resize(scene.indenters.size());
    for (std::size_t i = 0; i < scene.indenters.size(); ++i) {
      IndenterResult& ir = s.indenters[i];
      ir.position_m = sim.indenter_position(i, sim.time_s());
      ir.reaction_force_n = c.indenter_force_n[i];
      ir.contact_elements = c.contact_elements[i];
      const double travel = (ir.position_m - sim.indenter_position(i, 0)).norm();
      const Vec3& f = ir.reaction_force_n;
      ir.history.push_back({sim.time_s(), f.x(), f.y(), f.z(), travel});
    }
    record_tori(scene, sim.time_s(), c, s.tori);
    if (progress) progress({sim.steps(), max_steps, sim.time_s(), s.final_residual, s.final_speed_ratio});
    const bool settled = tol > 0 && at_equilibrium(sim, c, scales, tol) && sim.time_s() >= travel_end;
    if (settled) {
      s.converged = true;
      s.stop_reason = "equilibrium";
      break;
    }
    if (sim.steps() >= max_steps) {
      if (sim.steps() < scene.stop.max_steps) s.stop_reason = "max_time";
      break;
    }
  }
  s.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (tol > 0) s.unconverged_reason = unconverged_reason(scene, lattice, el, sim, s, check_every);
  if (!s.unconverged_reason.empty()) s.converged = false;

  FinalState& st = out.state;
  sim.download(st.displacement_m, st.velocity_m_s);
  const std::size_t n = lattice.element_count();
  st.position_m.resize(3 * n);
  for (std::size_t e = 0; e < n; ++e) {
    const Vec3 X = lattice.rest_position(e);
    for (int k = 0; k < 3; ++k) st.position_m[3 * e + k] = X[k] + st.displacement_m[3 * e + k];
  }
  s.volume_change = compute_element_measures(lattice, el.youngs_modulus_pa, st);
  // The constraint's mesh when there is one; else built here (milliseconds, docs/SURFACE.md).
  const SurfaceMesh built = sim.surface_mesh() ? SurfaceMesh{} : build_surface(lattice);
  const SurfaceMesh& surface = sim.surface_mesh() ? *sim.surface_mesh() : built;
  const double rest_volume = enclosed_volume_m3(surface, element_positions_m(lattice));
  if (rest_volume != 0) s.surface_volume_change = enclosed_volume_m3(surface, st.position_m) / rest_volume - 1;
  if (std::any_of(st.volumetric_strain.begin(), st.volumetric_strain.end(), [](double j) { return j <= -1; }))
    refuse_indenter_in_held_tissue(scene, lattice, el, sim);  // crushed elements: the cause, when it is one
  require_no_inverted_element(lattice, el, st);

  s.elements = n;
  s.connections = lattice.connection_count;
  s.fixed_elements = el.held_count;
  s.steps = sim.steps();
  s.dt_s = sim.dt_s();
  s.dt_auto = sim.time_step().automatic;
  s.simulated_time_s = sim.time_s();
  s.steps_per_second = s.wall_time_s > 0 ? double(s.steps) / s.wall_time_s : 0;
  s.max_displacement_m = c.max_displacement_m;
  s.device_name = sim.context().info.name;
  s.precision = sim.precision() == Precision::Double ? "double" : "float";
  s.integrator = integrator_name(scene.solver.integrator);
  for (const TrackSpec& t : scene.tracks) {
    TrackedPointResult r;
    r.name = t.name;
    r.point_m = t.point_m;
    r.element = std::int64_t(nearest_element(lattice, t.point_m));
    r.rest_m = lattice.rest_position(std::size_t(r.element));
    for (int k = 0; k < 3; ++k) r.displacement_m[k] = st.displacement_m[3 * r.element + k];
    s.tracked.push_back(r);
  }
  return out;
}

}  // namespace vb
