#pragma once
/// Checks that keep a run's contact honest (docs/PHYSICS.md, "Indenters", "Contact limits"):
/// rigid obstacles that move too far in one step, that start inside the body, or that are driven
/// into held tissue. Each throws vb::Error with its own message, or returns a description.
#include <optional>
#include <string>
#include <vector>

#include "engine/error.hpp"
#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/element_setup.hpp"

namespace vb {

/// Contact that a run cannot keep: an indenter or a torus too fast for the lattice, one starting
/// inside the body, one driven into held tissue. The command line exits with status 4 for it
/// (docs/OUTPUTS.md).
class ContactError : public Error {
 public:
  using Error::Error;
};

/// The farthest an indenter or a torus tube may move in one time step, in spacings. An element it
/// reaches within a step lands inside it and is put back on its surface along the surface normal:
/// the deeper it lands, the further that is from where the surface met it (a punch's rim throws
/// it onto the side wall, a ball past its centre throws it out of the far side).
inline constexpr double kMaxObstacleTravelPerStep = 0.1;

/// Throws when an indenter (its velocity, or a segment of its recorded path) or a torus tube (its
/// inflation rates) moves more than kMaxObstacleTravelPerStep·spacing in a step of dt_s; the
/// message gives the largest safe speed at this dt.
void check_obstacle_speeds(const Scene& scene, double spacing_m, double dt_s);

/// Throws when a free element's centre starts deeper than the contact band (10⁻³·h) inside an
/// indenter or a torus tube: the first step would throw it out along the surface normal, not
/// where a press would put it. position_m: element positions at t = 0 (n×3, m, world frame);
/// inverse_mass: 0 for held elements (those may overlap a tube or an indenter); indenter_at_m:
/// each indenter's reference point at t = 0.
void check_obstacles_start_outside(const Scene& scene, const Lattice& lattice, const std::vector<double>& position_m,
                                   const std::vector<double>& inverse_mass, const std::vector<Vec3>& indenter_at_m);

/// A description when an indenter, at indenter_now_m, holds held elements (an anchor or rigid
/// tissue) deeper than the contact band that it did not hold at indenter_start_m: it has been
/// driven into them, and the free tissue between is crushed (no time step helps). Positions as
/// above; free elements are not looked at.
std::optional<std::string> indenter_in_held_tissue(const Scene& scene, const Lattice& lattice,
                                                   const std::vector<double>& position_m,
                                                   const std::vector<double>& inverse_mass,
                                                   const std::vector<Vec3>& indenter_start_m,
                                                   const std::vector<Vec3>& indenter_now_m);

class Simulator;

/// Before a run's first step: the speeds (check_obstacle_speeds) and, with
/// `refuse_penetrating_start`, the start (check_obstacles_start_outside) of the scene's indenters
/// and tori, for the simulator's state. A run that starts overlapping a device on purpose (the
/// reproducibility study turns the patient under a fixed device) passes false.
void check_contact_before_run(const Scene& scene, const Lattice& lattice, const ElementArrays& el, const Simulator& sim,
                              bool refuse_penetrating_start = true);

/// Throws indenter_in_held_tissue's description for the simulator's time, if any: the cause of a
/// run that blew up or crushed elements, rather than its time step.
void refuse_indenter_in_held_tissue(const Scene& scene, const Lattice& lattice, const ElementArrays& el,
                                    const Simulator& sim);

}  // namespace vb
