#pragma once
/// What a run that went unstable is told: the cause its evidence points to, each with its own
/// message (docs/PHYSICS.md, "When a run goes unstable"), and the check that refuses, before the
/// run, a part that nothing holds.
#include <cstddef>
#include <string>
#include <vector>

#include "engine/error.hpp"
#include "engine/sim/simulator.hpp"

namespace vb {

/// A run that went unstable (non-finite state, runaway motion): the message says which cause the
/// run's evidence points to (a too-large dt, an unanchored part, a tissue too soft for its weight,
/// or what drives the model). The command line exits with its own status for it (4).
class InstabilityError : public Error {
 public:
  using Error::Error;
};

/// A connected part of the lattice (26-neighbour) with no held element.
struct FreePart {
  std::size_t elements = 0;
  std::size_t first_element = 0;  ///< its lowest element index
};

/// The parts of the lattice that no held element anchors, largest first.
std::vector<FreePart> unanchored_parts(const Lattice& lattice, const ElementArrays& elements);

/// Refuses a run that cannot reach equilibrium because a part is free to fall: gravity on, an
/// equilibrium test on, and no indenter or torus that could hold the part up.
void require_anchored(const Scene& scene, const Lattice& lattice, const ElementArrays& elements);

/// x to 3 significant digits, for messages
std::string number_text(double x);

/// "element E (voxel i,j,k) of tissue 'T'"
std::string element_name(const Lattice& lattice, std::size_t element);

/// Throws InstabilityError for check c: the step, time and element (`element_role`: " at " the
/// fastest, or ", the first being " the first non-finite), and the cause. A too-large dt is
/// blamed only when dt is above the estimated stable limit; within it the message names an
/// unanchored part, a tissue too soft to carry its weight, or else the loads and contacts that
/// drive the model, without a step to try.
[[noreturn]] void report_instability(const Scene& scene, const Lattice& lattice, const ElementArrays& elements,
                                     const Simulator& sim, const StateCheck& c, const std::string& what,
                                     const std::string& element_role);

}  // namespace vb
