#include "engine/sim/reference_state.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "engine/error.hpp"
#include "engine/sim/run.hpp"

namespace vb {
namespace {

/// true when the element's neighbours span 3-D (det Σ d·dᵀ ≥ ½, the test the hyperelastic fit
/// uses). An element of a one-voxel sheet or strand has none across it, so no force across it at
/// its CT position: no rest shape can hold it there against gravity across the sheet.
bool neighbours_span_3d(const Lattice& lattice, std::size_t e) {
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero();
  const auto nb = lattice.neighbours(e);
  for (std::size_t d = 0; d < nb.size(); ++d) {
    if (nb[d] < 0) continue;
    const auto& o = neighbour_offsets()[d];
    const Vec3 v(o[0], o[1], o[2]);
    B += v * v.transpose();
  }
  return B.determinant() >= 0.5;
}

}  // namespace

Scene reference_state_scene(const Scene& scene) {
  Scene s = scene;
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = scene.reference_state.ct_gravity_m_s2;
  s.gravity.posture = scene.reference_state.ct_posture;
  for (AnchorSpec& a : s.anchors) a.rpy_deg = Vec3::Zero();
  s.indenters.clear();
  s.tori.clear();
  s.volume = VolumeSpec{};
  s.reproducibility = ReproducibilitySpec{};
  s.solver.integrator = Integrator::Relaxation;
  s.solver.dt_s.reset();
  s.solver.dt_safety = 0.9;
  // The displacement error of a solve scales with its residual; the fixed point needs it small.
  s.stop.equilibrium = scene.stop.equilibrium > 0 ? std::min(scene.stop.equilibrium, 1e-6) : 1e-6;
  s.stop.max_time_s = INFINITY;
  s.output.frames_every = 0;
  return s;
}

ReferenceState estimate_reference_state(const Scene& scene, const Lattice& lattice, const ClContext& cl,
                                        const std::function<void(const ReferenceIteration&)>& on_iteration,
                                        const std::function<void(const RunProgress&)>& on_step) {
  return estimate_reference_state(scene, lattice, make_element_arrays(reference_state_scene(scene), lattice), cl, {},
                                  on_iteration, on_step);
}

ReferenceState estimate_reference_state(const Scene& scene, const Lattice& lattice, const ElementArrays& el,
                                        const ClContext& cl, const std::vector<double>& first_offset_m,
                                        const std::function<void(const ReferenceIteration&)>& on_iteration,
                                        const std::function<void(const RunProgress&)>& on_step) {
  const Scene ct = reference_state_scene(scene);  // the simulator keeps a reference: it lives as long as sim
  Simulator sim(ct, lattice, el, cl);
  return estimate_reference_state(sim, scene, lattice, el, first_offset_m, on_iteration, on_step);
}

ReferenceState estimate_reference_state(Simulator& sim, const Scene& scene, const Lattice& lattice,
                                        const ElementArrays& el, const std::vector<double>& first_offset_m,
                                        const std::function<void(const ReferenceIteration&)>& on_iteration,
                                        const std::function<void(const RunProgress&)>& on_step) {
  ReferenceState out;
  const auto start = std::chrono::steady_clock::now();
  const Scene ct = reference_state_scene(scene);
  const std::size_t n = lattice.element_count();
  // The residual is measured over the free elements that can rest at their CT position. The
  // others cannot be corrected by their own miss (it only winds their rest shape up until a solve
  // fails): they take the mean correction of their measured neighbours (none: no correction).
  std::vector<std::uint8_t> measured(n, 0);
  std::size_t free = 0;
  for (std::size_t e = 0; e < n; ++e) {
    if (el.inverse_mass[e] == 0) continue;
    if (neighbours_span_3d(lattice, e)) measured[e] = 1, ++free;
    else ++out.unsupported_elements;
  }
  std::vector<std::vector<std::size_t>> follows(n);
  for (std::size_t e = 0; e < n; ++e)
    if (el.inverse_mass[e] != 0 && !measured[e])
      for (const std::int32_t j : lattice.neighbours(e))
        if (j >= 0 && measured[std::size_t(j)]) follows[e].push_back(std::size_t(j));

  out.rest_offset_m = first_offset_m.size() == 3 * n ? first_offset_m : std::vector<double>(3 * n, 0.0);
  const std::vector<double> at_rest(3 * n, 0.0);
  // One forward solve from the CT with rest offsets u0: where the model lands (u*), or nothing
  // when the solve goes unstable (rest offsets too far from any sensible shape).
  const auto land = [&](const std::vector<double>& u0, int it) -> std::optional<RunOutput> {
    sim.set_rest_offsets(u0);
    sim.upload(el.displacement_m, at_rest);  // start from the CT (held elements at their CT pose)
    sim.restart_clock();
    RunOutput run;
    try {
      run = run_simulation(ct, lattice, el, sim, on_step);
    } catch (const Error&) {
      if (it == 1) throw;  // unstable from the CT itself: the scene's problem, reported as such
      return std::nullopt;
    }
    require(run.summary.converged,
            "the unloaded reference state's forward solve " + std::to_string(it) + " stopped at " +
                run.summary.stop_reason + " after " + std::to_string(run.summary.steps) +
                " steps without reaching equilibrium",
            "reference_state", "raise stop.max_steps, or check that the model is held (anchors) under the CT's gravity");
    return run;
  };
  const auto measure = [&](const std::vector<double>& u, int it, std::int64_t steps) {
    double max_sq = 0, sum_sq = 0;  // over free elements: how far the model lands from the CT
    for (std::size_t e = 0; e < n; ++e) {
      if (!measured[e]) continue;
      const double sq = u[3 * e] * u[3 * e] + u[3 * e + 1] * u[3 * e + 1] + u[3 * e + 2] * u[3 * e + 2];
      max_sq = std::max(max_sq, sq);
      sum_sq += sq;
    }
    return ReferenceIteration{it, std::sqrt(max_sq), free ? std::sqrt(sum_sq / double(free)) : 0.0, steps};
  };

  // Sellier's step u0 ← u0 − β·u*, β = 1 unless a step made the landing worse (RMS miss) or
  // the solve unstable: then it is retried from the last accepted u0 with β halved (a loosely held
  // flap at a crop edge can swing too far with a full step), and β grows back after a good step.
  std::vector<double> landed;  // u* of the accepted u0
  double beta = 1;
  for (int it = 1; it <= scene.reference_state.max_iterations; ++it) {
    std::vector<double> trial = out.rest_offset_m;
    if (it > 1)
      for (std::size_t e = 0; e < n; ++e) {
        if (measured[e]) {
          for (int c = 0; c < 3; ++c) trial[3 * e + c] -= beta * landed[3 * e + c];
        } else {
          for (const std::size_t j : follows[e])
            for (int c = 0; c < 3; ++c) trial[3 * e + c] -= beta * landed[3 * j + c] / double(follows[e].size());
        }
      }
    const std::optional<RunOutput> run = land(trial, it);
    ReferenceIteration r = run ? measure(run->state.displacement_m, it, run->summary.steps)
                               : ReferenceIteration{it, INFINITY, INFINITY, 0};
    r.step = beta;
    out.steps += r.steps;
    out.history.push_back(r);
    if (on_iteration) on_iteration(r);
    if (it > 1 && !(r.residual_rms_m < out.residual_rms_m)) {  // worse: retry with a shorter step
      beta *= 0.5;
      if (beta < 1.0 / 64) break;
      continue;
    }
    out.rest_offset_m = std::move(trial);
    landed = run->state.displacement_m;
    out.residual_max_m = r.residual_max_m;
    out.residual_rms_m = r.residual_rms_m;
    beta = std::min(1.0, 2 * beta);
    if (r.residual_max_m <= scene.reference_state.tolerance_m) {
      out.converged = true;
      break;
    }
  }
  for (std::size_t e = 0; e < n; ++e)
    out.max_rest_offset_m = std::max(out.max_rest_offset_m, Vec3(out.rest_offset_m[3 * e], out.rest_offset_m[3 * e + 1],
                                                                 out.rest_offset_m[3 * e + 2]).norm());
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace vb
