#include "engine/sim/contact_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "engine/device/torus.hpp"
#include "engine/error.hpp"
#include "engine/probe/indenter_shape.hpp"
#include "engine/sim/simulator.hpp"

namespace vb {
namespace {

constexpr double kContactBand = 1e-3;  // of a spacing, as REAL_CONTACT_TOL (kernels/common.cl)

const char* kind_name(IndenterSpec::Kind k) {
  switch (k) {
    case IndenterSpec::Kind::Plate: return "plate";
    case IndenterSpec::Kind::Cylinder: return "cylinder";
    case IndenterSpec::Kind::Capsule: return "capsule";
    case IndenterSpec::Kind::Sphere: break;
  }
  return "sphere";
}

std::string indenter_name(const IndenterSpec& ind, std::size_t i) {
  return "indenter " + std::to_string(i + 1) + " (" + kind_name(ind.kind) + ")";
}

Vec3 element_position(const std::vector<double>& x, std::size_t e) { return {x[3 * e], x[3 * e + 1], x[3 * e + 2]}; }

[[noreturn]] void too_fast(const std::string& what, const std::string& where, double speed_m_s, double h, double dt) {
  const double safe = kMaxObstacleTravelPerStep * h / dt;
  char text[400], hint[300];
  std::snprintf(text, sizeof text,
                "%s moves %.3g mm per time step (%.3g m/s at dt = %.3g s), more than %.2g of the spacing "
                "(%.3g mm): the tissue it reaches within a step lands deep inside it, and contact is lost "
                "or thrown to the wrong side",
                what.c_str(), 1e3 * speed_m_s * dt, speed_m_s, dt, kMaxObstacleTravelPerStep, 1e3 * h);
  std::snprintf(hint, sizeof hint, "the largest safe speed at this dt is %.3g m/s: move it slower, or set a smaller solver.dt",
                safe);
  throw ContactError(text, where, hint);
}

}  // namespace

void check_obstacle_speeds(const Scene& scene, double h, double dt) {
  const double limit = kMaxObstacleTravelPerStep * h;
  for (std::size_t i = 0; i < scene.indenters.size(); ++i) {
    const IndenterSpec& ind = scene.indenters[i];
    const std::string where = "indenter " + std::to_string(i + 1);
    if (ind.path.empty()) {
      if (ind.velocity_m_s.norm() * dt > limit) too_fast(indenter_name(ind, i), where + " velocity", ind.velocity_m_s.norm(), h, dt);
      continue;
    }
    for (std::size_t k = 0; k + 1 < ind.path.size(); ++k) {
      const PathKnot &a = ind.path[k], &b = ind.path[k + 1];
      const double speed = (b.position_m - a.position_m).norm() / (b.time_s - a.time_s);
      if (speed * dt > limit)
        too_fast(indenter_name(ind, i) + " between rows " + std::to_string(k + 1) + " and " + std::to_string(k + 2) +
                     " of " + ind.path_file,
                 where + " path", speed, h, dt);
    }
  }
  for (const TorusSpec& t : scene.tori)
    for (std::size_t k = 0; k + 1 < t.schedule.size(); ++k) {
      const TorusKnot &a = t.schedule[k], &b = t.schedule[k + 1];
      const double span = b.time_s - a.time_s;
      const double speed = (std::abs(b.minor_radius_m - a.minor_radius_m) + std::abs(b.major_radius_m - a.major_radius_m)) / span;
      if (speed * dt > limit) too_fast("torus '" + t.name + "' (its tube surface)", "device.torus " + t.name, speed, h, dt);
    }
}

void check_obstacles_start_outside(const Scene& scene, const Lattice& lattice, const std::vector<double>& x,
                                   const std::vector<double>& inverse_mass, const std::vector<Vec3>& indenter_at_m) {
  const double band = kContactBand * lattice.spacing_m;
  const auto refuse = [&](const std::string& what, const std::string& where, std::size_t count, double deepest,
                          const std::string& hint) {
    char text[300];
    std::snprintf(text, sizeof text, "%s starts inside the body: %zu free element%s up to %.3g mm inside it at t = 0",
                  what.c_str(), count, count == 1 ? " lies" : "s lie", 1e3 * deepest);
    throw ContactError(text, where, hint);
  };
  for (std::size_t i = 0; i < scene.indenters.size(); ++i) {
    std::size_t inside = 0;
    double deepest = 0;
    for (std::size_t e = 0; e < lattice.element_count(); ++e) {
      if (inverse_mass[e] == 0) continue;
      const double d = indenter_signed_distance(scene.indenters[i], indenter_at_m[i], element_position(x, e));
      if (d < -band) ++inside, deepest = std::max(deepest, -d);
    }
    if (inside > 0)
      refuse(indenter_name(scene.indenters[i], i), "indenter " + std::to_string(i + 1) + " start", inside, deepest,
             "start it outside the tissue (touching is fine: within 0.001 of a spacing) and move it in");
  }
  for (const TorusSpec& t : scene.tori) {
    std::size_t inside = 0;
    double deepest = 0;
    for (std::size_t e = 0; e < lattice.element_count(); ++e) {
      if (inverse_mass[e] == 0) continue;
      const double d = torus_signed_distance(t, 0.0, element_position(x, e));
      if (d < -band) ++inside, deepest = std::max(deepest, -d);
    }
    if (inside > 0)
      refuse("torus '" + t.name + "'", "device.torus " + t.name, inside, deepest,
             "start with a tube that clears the tissue (its first inflation knot) and inflate it onto the body");
  }
}

std::optional<std::string> indenter_in_held_tissue(const Scene& scene, const Lattice& lattice,
                                                   const std::vector<double>& x,
                                                   const std::vector<double>& inverse_mass,
                                                   const std::vector<Vec3>& indenter_start_m,
                                                   const std::vector<Vec3>& indenter_now_m) {
  const double band = kContactBand * lattice.spacing_m;
  for (std::size_t i = 0; i < scene.indenters.size(); ++i) {
    const IndenterSpec& ind = scene.indenters[i];
    std::size_t reached = 0;
    double deepest = 0;
    for (std::size_t e = 0; e < lattice.element_count(); ++e) {
      if (inverse_mass[e] != 0) continue;
      const Vec3 p = element_position(x, e);
      const double d = indenter_signed_distance(ind, indenter_now_m[i], p);
      if (d >= -band || indenter_signed_distance(ind, indenter_start_m[i], p) < -band) continue;
      ++reached, deepest = std::max(deepest, -d);
    }
    if (reached == 0) continue;
    char text[300];
    std::snprintf(text, sizeof text,
                  "%s has been driven %.3g mm into %zu held element%s (an anchor or rigid tissue): the free tissue "
                  "between them is crushed",
                  indenter_name(ind, i).c_str(), 1e3 * deepest, reached, reached == 1 ? "" : "s");
    return std::string(text);
  }
  return std::nullopt;
}

namespace {

std::vector<double> positions_now(const Lattice& lattice, const Simulator& sim) {
  std::vector<double> u, v;
  sim.download(u, v);
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    const Vec3 X = lattice.rest_position(e);
    for (int k = 0; k < 3; ++k) u[3 * e + k] += X[k];
  }
  return u;
}

std::vector<Vec3> indenters_at(const Scene& scene, const Simulator& sim, double t_s) {
  std::vector<Vec3> at;
  for (std::size_t i = 0; i < scene.indenters.size(); ++i) at.push_back(sim.indenter_position(i, t_s));
  return at;
}

}  // namespace

void check_contact_before_run(const Scene& scene, const Lattice& lattice, const ElementArrays& el, const Simulator& sim,
                              bool refuse_penetrating_start) {
  check_obstacle_speeds(scene, lattice.spacing_m, sim.dt_s());
  if (!refuse_penetrating_start || sim.steps() > 0 || (scene.indenters.empty() && scene.tori.empty())) return;
  check_obstacles_start_outside(scene, lattice, positions_now(lattice, sim), el.inverse_mass,
                                indenters_at(scene, sim, 0.0));
}

void refuse_indenter_in_held_tissue(const Scene& scene, const Lattice& lattice, const ElementArrays& el,
                                    const Simulator& sim) {
  if (scene.indenters.empty()) return;
  if (auto crushed = indenter_in_held_tissue(scene, lattice, positions_now(lattice, sim), el.inverse_mass,
                                             indenters_at(scene, sim, 0.0), indenters_at(scene, sim, sim.time_s())))
    throw ContactError(*crushed + " (t = " + std::to_string(sim.time_s()) + " s)", "indenter", "stop it before it reaches them (its travel_time), or anchor less of the model");
}

}  // namespace vb
