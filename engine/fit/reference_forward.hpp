#pragma once
/// Forward solves of a fit from the unloaded reference state (docs/FIT.md, "Unloaded reference
/// state"): the model's image is a loaded shape (the CT posture's), so for each trial set of
/// moduli the rest shape that lands on the image under the CT's gravity is estimated (Sellier's
/// fixed point, engine/sim/reference_state.hpp), then the model is solved under the observed
/// posture's gravity from the image resting on it.
#include <memory>

#include "engine/fit/fit_spec.hpp"
#include "engine/fit/forward_model.hpp"
#include "engine/sim/simulator.hpp"

namespace vb {

/// Whether a fit solves from the unloaded reference state: fit.unloaded_reference, unset: exactly
/// when the scene has [reference_state]. Throws vb::Error when it is asked for without
/// [reference_state], or with a fit.from_posture / from_gravity other than the CT's posture.
bool use_unloaded_reference(const Scene& scene, const FitSpec& fit);

/// The two simulators of these solves, kept across a fit's solves: built by the first, given
/// each later solve's moduli by Simulator::set_materials.
struct UnloadedReferenceSimulators {
  Scene reference_scene;                 ///< the fixed point's scene (reference_state_scene): its simulator refers to it
  std::unique_ptr<Simulator> reference;  ///< the fixed point's forward solves, under the CT's gravity
  std::unique_ptr<Simulator> posture;    ///< the solve under the scene's gravity
};

/// One forward solve: rest offsets for these element arrays (starting from warm's, which cuts the
/// fixed-point iterations to one or two when the moduli changed little), then equilibrium under
/// the scene's gravity from the image (warm: from warm's state), on `sims`. `from_m` is zero (the
/// image is the equilibrium in the CT posture, within [reference_state] tolerance_mm), so the
/// posture change is `to_m`. Throws vb::Error when a solve does not reach equilibrium.
/// `timing`: the phases' times and the steps added to it (the fixed point's solves count as
/// relaxation, their simulator's new moduli as setup).
ForwardSolution solve_from_unloaded_reference(const Scene& scene, const Lattice& lattice, const ElementArrays& elements,
                                              const ClContext& cl, const ForwardSolution* warm,
                                              UnloadedReferenceSimulators& sims, JacobianTiming* timing = nullptr);

}  // namespace vb
