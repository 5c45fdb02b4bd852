#include "engine/sim/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "engine/device/torus.hpp"
#include "engine/error.hpp"
#include "engine/results/element_measures.hpp"
#include "engine/surface/enclosed_volume.hpp"

namespace vb {
namespace {

const char* integrator_name(Integrator i) {
  return i == Integrator::Heun ? "heun" : i == Integrator::Relaxation ? "relaxation" : "symplectic_euler";
}

/// The tissue whose free elements have the largest stability modulus per mass: the one that sets
/// the estimated stable step (docs/PHYSICS.md, sections 3 and 8).
const std::string& step_limiting_tissue(const Lattice& lattice, const ElementArrays& el) {
  std::size_t stiffest = 0;
  double highest = -1;
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    const double omega_sq = el.stability_modulus_pa[e] * el.inverse_mass[e];
    if (omega_sq > highest) highest = omega_sq, stiffest = e;
  }
  return lattice.tissue_names[lattice.tissue_of_element[stiffest]];
}

std::string element_name(const Lattice& lattice, std::size_t e) {
  const auto ijk = lattice.voxel_ijk(e);
  return "element " + std::to_string(e) + " (voxel " + std::to_string(ijk[0]) + "," + std::to_string(ijk[1]) + "," +
         std::to_string(ijk[2]) + ") of tissue '" + lattice.tissue_names[lattice.tissue_of_element[e]] + "'";
}

/// Throws the instability error: step, time, the element (`element_role`: the fastest, or the first
/// non-finite) with its voxel and tissue, and a step to try: dt_safety × the estimated stable limit
/// (what "auto" would use), but at most half the step that failed, so the hint always lowers dt.
[[noreturn]] void report_instability(const Scene& scene, const Lattice& lattice, const ElementArrays& el,
                                     const Simulator& sim, const StateCheck& c, const std::string& what,
                                     const std::string& element_role) {
  std::ostringstream msg;
  msg << "simulation went unstable at step " << sim.steps() << " (t = " << sim.time_s() << " s): " << what;
  if (c.fastest_element >= 0) msg << element_role << element_name(lattice, std::size_t(c.fastest_element));
  const double limit = sim.time_step().stable_limit_s;
  double suggested = 0.5 * sim.dt_s();
  if (limit > 0 && std::isfinite(limit)) suggested = std::min(suggested, scene.solver.dt_safety * limit);
  std::ostringstream hint;
  hint << "use a smaller solver.dt: try solver.dt = " << suggested << " s (now " << sim.dt_s()
       << " s; estimated stable limit " << limit << " s, set by tissue '" << step_limiting_tissue(lattice, el)
       << "'), or more damping";
  throw Error(msg.str(), "solver", hint.str());
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

}  // namespace

EquilibriumScales equilibrium_scales(const Lattice& lattice, const ElementArrays& el) {
  // Over the free elements: held tissue (rigid bone at 1 GPa, say) must not loosen the criterion.
  double E_max = 0, m_min = INFINITY;
  for (std::size_t e = 0; e < el.mass_kg.size(); ++e) {
    if (el.inverse_mass[e] == 0) continue;
    E_max = std::max(E_max, el.youngs_modulus_pa[e]);
    m_min = std::min(m_min, el.mass_kg[e]);
  }
  const double h = lattice.spacing_m;
  return {E_max * h * h, std::sqrt(E_max / (m_min / (h * h * h))),
          h * Eigen::Vector3d(lattice.dims[0], lattice.dims[1], lattice.dims[2]).norm()};
}

bool at_equilibrium(const Simulator& sim, const StateCheck& c, const EquilibriumScales& scales, double tol) {
  if (c.max_residual_n > tol * scales.force_n) return false;
  // A dynamic run's speed test bounds a like distance, tol·c / ω_min. The residual alone let
  // relaxation stop 1% of the displacement from equilibrium on a soft column at 1e-5
  // (docs/BENCHMARKS.md).
  if (sim.relaxing()) return c.max_speed_m_s / std::sqrt(sim.relaxation_omega_sq()) <= tol * scales.size_m;
  return c.max_speed_m_s <= tol * scales.wave_speed_m_s;
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
                         const std::function<void(const RunProgress&)>& progress) {
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
  const std::int64_t check_every = std::max(1, scene.solver.check_every);
  const std::int64_t frames_every = scene.output.frames_every;
  std::int64_t max_steps = scene.stop.max_steps;
  const double time_steps = std::ceil(scene.stop.max_time_s / sim.dt_s() - 1e-9);  // compared before the cast
  if (time_steps < double(max_steps)) max_steps = std::max<std::int64_t>(0, std::int64_t(time_steps));

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

    s.final_residual = c.max_residual_n / scales.force_n;
    s.final_speed_ratio = c.max_speed_m_s / scales.wave_speed_m_s;
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
