#include "engine/fit/reference_forward.hpp"

#include <algorithm>

#include "engine/error.hpp"
#include "engine/fit/relax_to_equilibrium.hpp"
#include "engine/sim/reference_state.hpp"
#include "engine/sim/run.hpp"
#include "engine/sim/simulator.hpp"

namespace vb {
namespace {

// 0.1 µm in double precision; float rounding (~1e-7 of the model's size) allows about 1 µm
constexpr double kFitReferenceTolerance_m = 1e-7, kFitReferenceToleranceFloat_m = 1e-6;

}  // namespace

bool use_unloaded_reference(const Scene& scene, const FitSpec& fit) {
  const bool on = fit.unloaded_reference.value_or(scene.reference_state.active);
  if (!on) return false;
  require(scene.reference_state.active, "fit.unloaded_reference needs the scene's [reference_state]", "fit.unloaded_reference",
          "add [reference_state] ct_posture = \"...\" (the posture of the model's image), or remove the key");
  if (fit.from_gravity_m_s2)
    require((*fit.from_gravity_m_s2 - scene.reference_state.ct_gravity_m_s2).norm() <= 1e-9 * (1 + fit.from_gravity_m_s2->norm()),
            "fit.from_posture differs from [reference_state]'s CT posture", "fit.from_posture",
            "with the unloaded reference state the image posture is [reference_state] ct_posture: leave "
            "fit.from_posture out, or set fit.unloaded_reference = false");
  return true;
}

ForwardSolution solve_from_unloaded_reference(const Scene& scene, const Lattice& lattice, const ElementArrays& el,
                                              const ClContext& cl, const ForwardSolution* warm,
                                              UnloadedReferenceSimulators& sims, JacobianTiming* timing) {
  PhaseLaps lap(timing);
  const std::size_t n = lattice.element_count();
  ForwardSolution out;
  // The fit differences solves whose moduli differ by a few percent: the rest offsets must be
  // far more exact than [reference_state] tolerance_mm needs for a simulation, or the fixed
  // point's miss (which depends on where it started) is noise in the Jacobian.
  Scene tight = scene;
  tight.reference_state.tolerance_m =
      std::min(scene.reference_state.tolerance_m, scene.solver.precision == Precision::Double
                                                      ? kFitReferenceTolerance_m
                                                      : kFitReferenceToleranceFloat_m);
  tight.reference_state.max_iterations = std::max(scene.reference_state.max_iterations, 50);
  const std::size_t built = std::size_t(!sims.reference) + std::size_t(!sims.posture);
  if (!sims.reference) {
    sims.reference_scene = reference_state_scene(tight);
    sims.reference = std::make_unique<Simulator>(sims.reference_scene, lattice, el, cl);
  } else {
    sims.reference->set_materials(el);
  }
  if (!sims.posture) sims.posture = std::make_unique<Simulator>(scene, lattice, el, cl);
  else sims.posture->set_materials(el);
  lap(&JacobianTiming::setup_s);
  const ReferenceState ref = estimate_reference_state(*sims.reference, tight, lattice, el,
                                                      warm ? warm->rest_offset_m : std::vector<double>{});
  lap(&JacobianTiming::relax_s);
  // Not within tolerance after max_iterations: the best estimate is kept (as `simulate` does);
  // the fit's residual then includes the estimate's miss, which ref.residual_max_m bounds.
  out.rest_offset_m = ref.rest_offset_m;
  out.steps = ref.steps;
  out.reference_solves = int(ref.history.size());
  out.from_m.assign(3 * n, 0.0);

  Simulator& sim = *sims.posture;
  sim.set_rest_offsets(ref.rest_offset_m);
  const std::vector<double> still(3 * n, 0.0);
  sim.upload(warm ? warm->to_m : el.displacement_m, still);
  lap(&JacobianTiming::upload_s);
  out.steps += relax_to_equilibrium(sim, scene, equilibrium_scales(lattice, el),
                                    scene.gravity.acceleration_m_s2, "to");
  lap(&JacobianTiming::relax_s);
  std::vector<double> v;
  sim.download(out.to_m, v);
  lap(&JacobianTiming::readback_s);
  if (timing) timing->add_solve(out.steps, n, built);
  return out;
}

}  // namespace vb
