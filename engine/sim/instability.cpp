#include "engine/sim/instability.hpp"

#include "engine/sim/contact_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "engine/error.hpp"

namespace vb {
namespace {

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

std::string part_text(const Lattice& lattice, const std::vector<FreePart>& parts) {
  std::size_t free = 0;
  for (const FreePart& p : parts) free += p.elements;
  return std::to_string(parts.size()) + " part" + (parts.size() > 1 ? "s" : "") + " of the model (" +
         std::to_string(free) + " of " + std::to_string(lattice.element_count()) +
         " elements; the largest has " + std::to_string(parts.front().elements) + ", among them " +
         element_name(lattice, parts.front().first_element) + ") " + (parts.size() > 1 ? "are" : "is") +
         " joined to no held element";
}

/// The free element whose tissue would sag most under gravity over the model's size L, as the
/// ratio ρ·g·L/E of that sag (ρ·g·L²/E) to L; 0 without gravity.
double worst_sag_ratio(const Scene& scene, const Lattice& lattice, const ElementArrays& el, std::size_t& worst) {
  if (!scene.gravity.active) return 0;
  const double h = lattice.spacing_m, g = scene.gravity.acceleration_m_s2.norm();
  const double L = h * std::sqrt(double(lattice.dims[0]) * lattice.dims[0] + double(lattice.dims[1]) * lattice.dims[1] +
                                 double(lattice.dims[2]) * lattice.dims[2]);
  double ratio = 0;
  for (std::size_t e = 0; e < el.mass_kg.size(); ++e) {
    if (el.inverse_mass[e] == 0) continue;
    const double r = el.youngs_modulus_pa[e] > 0 ? el.mass_kg[e] / (h * h * h) * g * L / el.youngs_modulus_pa[e] : INFINITY;
    if (r > ratio) ratio = r, worst = e;
  }
  return ratio;
}

}  // namespace

std::string number_text(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

std::string element_name(const Lattice& lattice, std::size_t e) {
  const auto ijk = lattice.voxel_ijk(e);
  return "element " + std::to_string(e) + " (voxel " + std::to_string(ijk[0]) + "," + std::to_string(ijk[1]) + "," +
         std::to_string(ijk[2]) + ") of tissue '" + lattice.tissue_names[lattice.tissue_of_element[e]] + "'";
}

std::vector<FreePart> unanchored_parts(const Lattice& lattice, const ElementArrays& el) {
  const std::size_t n = lattice.element_count();
  std::vector<char> seen(n, 0);
  std::vector<std::size_t> stack;
  std::vector<FreePart> parts;
  for (std::size_t start = 0; start < n; ++start) {
    if (seen[start]) continue;
    FreePart part{0, start};
    bool held = false;
    seen[start] = 1;
    stack.assign(1, start);
    while (!stack.empty()) {
      const std::size_t e = stack.back();
      stack.pop_back();
      ++part.elements;
      held = held || el.inverse_mass[e] == 0;
      for (const std::int32_t j : lattice.neighbours(e))
        if (j >= 0 && !seen[std::size_t(j)]) seen[std::size_t(j)] = 1, stack.push_back(std::size_t(j));
    }
    if (!held) parts.push_back(part);
  }
  std::stable_sort(parts.begin(), parts.end(), [](const FreePart& a, const FreePart& b) { return a.elements > b.elements; });
  return parts;
}

void require_anchored(const Scene& scene, const Lattice& lattice, const ElementArrays& el) {
  if (!scene.gravity.active || !(scene.stop.equilibrium > 0) || !scene.indenters.empty() || !scene.tori.empty()) return;
  const std::vector<FreePart> parts = unanchored_parts(lattice, el);
  if (parts.empty()) return;
  throw Error(part_text(lattice, parts) + ": under gravity it falls freely and never reaches equilibrium", "anchor",
              el.held_count == 0 ? "add an [anchor.NAME] (or a rigid tissue) that holds the model"
                                 : "anchor the part too, or leave it out of the model (model.keep, a region of interest)");
}

void report_instability(const Scene& scene, const Lattice& lattice, const ElementArrays& el, const Simulator& sim,
                        const StateCheck& c, const std::string& what, const std::string& element_role) {
  refuse_indenter_in_held_tissue(scene, lattice, el, sim);  // the cause, when it is one
  std::ostringstream msg;
  msg << "simulation went unstable at step " << sim.steps() << " (t = " << sim.time_s() << " s): " << what;
  if (c.fastest_element >= 0) msg << element_role << element_name(lattice, std::size_t(c.fastest_element));
  const double limit = sim.time_step().stable_limit_s, dt = sim.dt_s();
  const bool limit_known = limit > 0 && std::isfinite(limit);
  if (!limit_known || dt > limit * (1 + 1e-9)) {
    // dt beyond the estimated stable limit: try dt_safety × the limit (what "auto" would use),
    // but at most half the step that failed, so the hint always lowers dt.
    double suggested = 0.5 * dt;
    if (limit_known) suggested = std::min(suggested, scene.solver.dt_safety * limit);
    std::ostringstream hint;
    hint << "use a smaller solver.dt: try solver.dt = " << suggested << " s (now " << dt
         << " s; estimated stable limit " << limit << " s, set by tissue '" << step_limiting_tissue(lattice, el)
         << "'), or more damping";
    throw InstabilityError(msg.str(), "solver", hint.str());
  }
  // dt within its stable limit: a smaller one would fail the same way, so the cause is physical.
  const std::string within = "; dt = " + number_text(dt) + " s is within its estimated stable limit (" +
                             number_text(limit) + " s), so a smaller step would not help";
  const std::vector<FreePart> parts = unanchored_parts(lattice, el);
  if (!parts.empty())
    throw InstabilityError(msg.str() + within + ": " + part_text(lattice, parts) + ", so the loads carry it away",
                           "anchor", "anchor every part (an [anchor.NAME] or a rigid tissue), or leave free parts out");
  std::size_t soft = 0;
  const double sag = worst_sag_ratio(scene, lattice, el, soft);
  if (sag > 1) {
    const std::string tissue = lattice.tissue_names[lattice.tissue_of_element[soft]];
    throw InstabilityError(msg.str() + within + ": tissue '" + tissue + "' (E = " +
                               number_text(el.youngs_modulus_pa[soft]) +
                               " Pa) is too soft to carry its own weight: gravity would sag it by about " +
                               number_text(sag) + " times the model's size",
                           "materials." + tissue, "check its modulus and its unit (Pa)");
  }
  throw InstabilityError(msg.str() + within + ": what drives the model does (an indenter, plate or torus pushing "
                                              "tissue through an anchor or held tissue, loads beyond what the tissue "
                                              "carries)",
                         "solver", "check the anchors, the indenters' travel and the materials");
}

}  // namespace vb
