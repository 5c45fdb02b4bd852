#include "engine/probe/press_line.hpp"

#include <chrono>
#include <cmath>

#include <Eigen/LU>

#include "engine/error.hpp"
#include "engine/probe/force_profile.hpp"
#include "engine/probe/indenter_shape.hpp"
#include "engine/probe/triangle_geometry.hpp"
#include "engine/results/element_measures.hpp"
#include "engine/sim/run.hpp"
#include "engine/surface/surface_area.hpp"

namespace vb {
namespace {

constexpr double kContactTol = 1e-3;  // of a spacing, as REAL_CONTACT_TOL (kernels/common.cl)
// The probe moves to each increment at most this many spacings per step, as the haptic loop does
// (0.25 h per 20 steps), so the increments do not change the answer (docs/PROBING.md, "Increments").
// Placed a whole increment deep at once, a triangle-contact (penalty) probe pushes the surface
// elements with k_p·increment; their fast contact mode is barely damped (relaxation damps the
// slowest mode), so they overshoot by about the increment, and 1 mm increments at h = 2 mm folded
// the layer below and lost the contact (docs/VALIDATION.md, "Probing: palpation and indenters"). A vertex-contact probe
// placed an increment deep projects the elements it lands on back onto its nearest surface: a
// punch throws those near its rim onto its side wall, where they no longer bear on its face, and
// an increment of a spacing lets the punch pass through the surface layer.
constexpr double kRampPerStep = 0.0125;

struct Relaxed {
  StateCheck check;
  std::int64_t steps = 0;
  double residual = 0;
  bool converged = false;
};

/// Steps until at_equilibrium holds at the scene's tolerance (engine/sim/run.hpp) or
/// stop.max_steps have run; not before `min_steps` (a probe still moving).
Relaxed relax(const Scene& scene, const Lattice& lattice, const ElementArrays& el, Simulator& sim,
              std::int64_t min_steps = 0) {
  const EquilibriumScales scales = equilibrium_scales(lattice, el);
  const double tol = scene.stop.equilibrium > 0 ? scene.stop.equilibrium : 1e-6;
  const std::int64_t every = std::max(1, scene.solver.check_every);
  Relaxed r;
  while (r.steps < scene.stop.max_steps) {
    const std::int64_t chunk = std::min(every, scene.stop.max_steps - r.steps);
    sim.advance(chunk);
    r.steps += chunk;
    r.check = sim.check();
    if (r.check.nonfinite_elements > 0 || !std::isfinite(r.check.max_speed_m_s))
      throw Error("probing went unstable: " + std::to_string(r.check.nonfinite_elements) + " elements have non-finite state",
                  "solver", "use a smaller solver.dt or smaller probe increments (more [probe] steps)");
    r.residual = r.check.residual_ratio;
    if (at_equilibrium(sim, r.check, scales, tol) && r.steps >= min_steps) {
      r.converged = true;
      break;
    }
  }
  return r;
}

std::vector<double> positions(const Lattice& lattice, const std::vector<double>& u) {
  std::vector<double> x(u.size());
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    const Vec3 X = lattice.rest_position(e);
    for (int k = 0; k < 3; ++k) x[3 * e + k] = X[k] + u[3 * e + k];
  }
  return x;
}

/// Travel along `dir` from `from` at which the indenter first touches an element at x (m), or with
/// triangle contact a surface triangle: scanned in steps of `step` (shorter than the indenter and
/// the spacing, so no element is stepped over), then bisected in the step where the nearest
/// element's (triangle's) signed distance first drops to zero.
double first_touch(const IndenterSpec& ind, const Vec3& from, const Vec3& dir, const std::vector<double>& x,
                   const SurfaceMesh& surface, double reach, double step) {
  const bool triangles = ind.contact_surface == IndenterSpec::Surface::Triangles;
  const auto gap = [&](double s) {
    if (triangles) return sphere_surface_gap_m(surface, x, from + s * dir, ind.radius_m);
    double g = INFINITY;
    for (std::size_t e = 0; e < x.size() / 3; ++e)
      g = std::min(g, indenter_signed_distance(ind, from + s * dir, Vec3(x[3 * e], x[3 * e + 1], x[3 * e + 2])));
    return g;
  };
  if (gap(0) <= 0) return 0;
  for (double lo = 0; lo < reach; lo += step) {
    double hi = lo + step;
    if (gap(hi) > 0) continue;
    for (int k = 0; k < 60 && hi - lo > 1e-9; ++k) (gap(0.5 * (lo + hi)) > 0 ? lo : hi) = 0.5 * (lo + hi);
    return hi;
  }
  return NAN;
}

}  // namespace

ProbeResult run_press_line(const Scene& scene, const Lattice& lattice, const ElementArrays& el, Simulator& sim,
                           const ProbeProgress& progress) {
  const ProbeSpec& p = scene.probe;
  require(p.active, "the scene has no [probe] section", "probe", "add [probe] (docs/SCENE.md)");
  require(p.indenter < scene.indenters.size(), "probe.indenter names no [[indenter]]", "probe.indenter");
  require(p.presses >= 1 && p.steps >= 1 && p.depth_m > 0, "probe needs presses ≥ 1, steps ≥ 1 and depth > 0", "probe");
  const IndenterSpec& ind = scene.indenters[p.indenter];
  const bool triangles = ind.contact_surface == IndenterSpec::Surface::Triangles;
  // A penalty probe placed deeper than its radius per increment could land behind the surface.
  require(!triangles || p.depth_m / p.steps < ind.radius_m,
          "the press increment (depth/steps = " + std::to_string(1e3 * p.depth_m / p.steps) +
              " mm) is not smaller than the triangle-contact probe's radius (" + std::to_string(1e3 * ind.radius_m) + " mm)",
          "probe.steps", "use more steps, so that each increment is below the radius");
  require(ind.path.empty(), "the probing indenter follows a recorded trajectory", "probe.indenter",
          "[probe] moves the indenter itself: remove its 'path'");
  const auto start_clock = std::chrono::steady_clock::now();
  const double h = lattice.spacing_m;
  const Vec3 dir = p.direction.normalized();
  const Vec3 extent = h * Vec3(lattice.dims[0], lattice.dims[1], lattice.dims[2]);
  ProbeResult out;

  // Settle with the indenter parked well outside the model (behind the first start point).
  const Vec3 parked = p.from_m - (2 * extent.norm() + 1.0) * dir;
  for (std::size_t i = 0; i < scene.indenters.size(); ++i)
    if (i == p.indenter) sim.place_indenter(i, parked);
  const Relaxed settle = relax(scene, lattice, el, sim);
  if (progress) progress(-1, 0, settle.residual);
  out.settle_steps = settle.steps;
  out.settle_residual = settle.residual;
  out.settled = settle.converged;
  out.settle_max_displacement_m = settle.check.max_displacement_m;
  out.total_steps = settle.steps;
  std::vector<double> u0, v0;
  sim.download(u0, v0);
  const std::vector<double> zero_v(v0.size(), 0.0);
  const std::vector<double> x0 = positions(lattice, u0);
  const SurfaceMesh surface = build_surface(lattice);

  for (int k = 0; k < p.presses; ++k) {
    PressResult press;
    const double f = p.presses > 1 ? double(k) / (p.presses - 1) : 0.0;
    Vec3 start = p.from_m + f * (p.to_m - p.from_m);
    press.position_m = (start - p.from_m).norm();
    if (p.from_contact) {
      double reach = 0;  // the indenter touches every element before its reference point travels this far
      for (std::size_t e = 0; e < x0.size() / 3; ++e)
        reach = std::max(reach, (Vec3(x0[3 * e], x0[3 * e + 1], x0[3 * e + 2]) - start).norm());
      const double step = 0.5 * (ind.kind == IndenterSpec::Kind::Plate ? h : std::min(h, ind.radius_m));
      const double touch = first_touch(ind, start, dir, x0, surface, reach, step);
      require(std::isfinite(touch), "press " + std::to_string(k + 1) + " never touches the model", "probe.from",
              "start the presses beside the model and point 'direction' at it");
      start += touch * dir;
    }
    press.start_m = start;
    sim.upload(u0, zero_v);
    std::vector<double> depths, forces;
    for (int j = 0; j <= p.steps; ++j) {
      PressSample sample;
      sample.depth_m = p.depth_m * j / p.steps;
      const Vec3 target = start + sample.depth_m * dir;
      std::int64_t ramp_steps = 0;
      if (j > 0) {
        const Vec3 from = start + (p.depth_m * (j - 1) / p.steps) * dir;
        ramp_steps = std::int64_t(std::ceil((target - from).norm() / (kRampPerStep * h)));
        const double t0 = sim.time_s();
        sim.set_indenter_motion(p.indenter, IndenterMotion::straight(from, target, t0, t0 + ramp_steps * sim.dt_s()));
      } else {
        sim.place_indenter(p.indenter, target);
      }
      const Relaxed r = relax(scene, lattice, el, sim, ramp_steps);
      out.total_steps += r.steps;
      if (!r.converged) ++out.unconverged_increments;
      if (progress) progress(k, j, r.residual);
      sample.force_n = r.check.indenter_force_n[p.indenter];
      sample.press_force_n = -sample.force_n.dot(dir);
      sample.contact_elements = r.check.contact_elements[p.indenter];
      sample.steps = r.steps;
      sample.residual = r.residual;
      sample.converged = r.converged;
      // Contact area: surface-area shares of the surface elements on the indenter's surface; with
      // triangle contact the areas of the triangles the sphere overlaps.
      std::vector<double> u, v;
      sim.download(u, v);
      const std::vector<double> x = positions(lattice, u);
      const Vec3 at = start + sample.depth_m * dir;
      if (triangles) {
        sample.contact_area_m2 = touched_triangle_area_m2(surface, x, at, ind.radius_m, 0.0);
      } else {
        const std::vector<double> area = element_surface_area_m2(surface, x);
        for (std::size_t e = 0; e < area.size(); ++e)
          if (area[e] > 0 && indenter_signed_distance(ind, at, Vec3(x[3 * e], x[3 * e + 1], x[3 * e + 2])) <= kContactTol * h)
            sample.contact_area_m2 += area[e];
      }
      // Folded elements (det F ≤ 0): the force is not the tissue's (check_folding).
      const FoldCheck fold = check_folding(lattice, u, el.inverse_mass);
      sample.min_det_f = std::min(sample.min_det_f, fold.min_det_f);
      sample.inverted_elements = fold.inverted_elements;
      press.min_det_f = std::min(press.min_det_f, sample.min_det_f);
      if (sample.inverted_elements > 0) {
        press.inverted = true;
        ++out.inverted_increments;
      }
      depths.push_back(sample.depth_m);
      forces.push_back(sample.press_force_n);
      press.samples.push_back(sample);
    }
    press.peak_force_n = forces.back();
    press.stiffness_n_m = (forces[forces.size() - 1] - forces[forces.size() - 2]) / (depths[depths.size() - 1] - depths[depths.size() - 2]);
    for (double F : p.at_force_n) press.depth_at_force_m.push_back(depth_at_force(depths, forces, F));
    out.presses.push_back(std::move(press));
  }
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_clock).count();
  return out;
}

}  // namespace vb
