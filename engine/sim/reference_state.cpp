#include "engine/sim/reference_state.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "engine/error.hpp"
#include "engine/sim/run.hpp"

namespace vb {

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
                                        const std::function<void(const ReferenceIteration&)>& on_iteration) {
  const auto start = std::chrono::steady_clock::now();
  const Scene ct = reference_state_scene(scene);
  const ElementArrays el = make_element_arrays(ct, lattice);
  Simulator sim(ct, lattice, el, cl);
  const std::size_t n = lattice.element_count();
  std::size_t free = 0;
  for (std::size_t e = 0; e < n; ++e) free += el.inverse_mass[e] != 0;

  ReferenceState out;
  out.rest_offset_m.assign(3 * n, 0.0);
  const std::vector<double> at_rest(3 * n, 0.0);
  for (int it = 1; it <= scene.reference_state.max_iterations; ++it) {
    sim.set_rest_offsets(out.rest_offset_m);
    sim.upload(el.displacement_m, at_rest);  // start from the CT (held elements at their CT pose)
    sim.restart_clock();
    const RunOutput run = run_simulation(ct, lattice, el, sim);
    require(run.summary.converged,
            "the unloaded reference state's forward solve " + std::to_string(it) + " stopped at " +
                run.summary.stop_reason + " after " + std::to_string(run.summary.steps) +
                " steps without reaching equilibrium",
            "reference_state", "raise stop.max_steps, or check that the model is held (anchors) under the CT's gravity");
    // How far the model, loaded from this rest shape, lands from the CT: the fixed point's residual.
    const std::vector<double>& u = run.state.displacement_m;
    double max_sq = 0, sum_sq = 0;
    for (std::size_t e = 0; e < n; ++e) {
      if (el.inverse_mass[e] == 0) continue;
      const double sq = u[3 * e] * u[3 * e] + u[3 * e + 1] * u[3 * e + 1] + u[3 * e + 2] * u[3 * e + 2];
      max_sq = std::max(max_sq, sq);
      sum_sq += sq;
    }
    ReferenceIteration r;
    r.iteration = it;
    r.residual_max_m = std::sqrt(max_sq);
    r.residual_rms_m = free ? std::sqrt(sum_sq / double(free)) : 0.0;
    r.steps = run.summary.steps;
    out.history.push_back(r);
    out.steps += r.steps;
    out.residual_max_m = r.residual_max_m;
    out.residual_rms_m = r.residual_rms_m;
    if (on_iteration) on_iteration(r);
    if (r.residual_max_m <= scene.reference_state.tolerance_m) {
      out.converged = true;
      break;
    }
    if (it == scene.reference_state.max_iterations) break;  // keep the offsets the residual is of
    for (std::size_t e = 0; e < n; ++e)
      if (el.inverse_mass[e] != 0)
        for (int c = 0; c < 3; ++c) out.rest_offset_m[3 * e + c] -= u[3 * e + c];
  }
  for (std::size_t e = 0; e < n; ++e)
    out.max_rest_offset_m = std::max(out.max_rest_offset_m, Vec3(out.rest_offset_m[3 * e], out.rest_offset_m[3 * e + 1],
                                                                 out.rest_offset_m[3 * e + 2]).norm());
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace vb
