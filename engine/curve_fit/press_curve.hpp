#pragma once
/// Quasi-static force–displacement curve of a press (voxbreast fit-curve, docs/FIT_CURVE.md):
/// the scene's indenter moves along its velocity direction level by level, and at each level the
/// model relaxes to equilibrium (the relaxation integrator, whatever the scene says) before the
/// force is read.
#include <vector>

#include "engine/sim/simulator.hpp"

namespace vb {

struct PressCurveOptions {
  std::size_t probe = 0;                    ///< the scene's indenter that presses
  std::int64_t max_steps_per_level = 0;  ///< more without equilibrium: vb::Error; 0: stop.max_steps
};

/// Forces (N) opposing the press at the given travels (m, ascending, ≥ 0) from the indenter's
/// start along its velocity direction; equilibrium as the scene's stop.equilibrium. Throws
/// vb::Error when the indenter has no velocity, a level does not settle, or the state blows up.
std::vector<double> press_curve_forces(const Scene& scene, const Lattice& lattice, const ElementArrays& elements,
                                       const ClContext& cl, const std::vector<double>& travel_m,
                                       const PressCurveOptions& options = {});

}  // namespace vb
