#include "engine/fit/forward_model.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "engine/error.hpp"
#include "engine/fit/initial_guess.hpp"
#include "engine/fit/material_scaling.hpp"
#include "engine/fit/relax_to_equilibrium.hpp"
#include "engine/fit/reference_forward.hpp"
#include "engine/sim/run.hpp"
#include "engine/sim/simulator.hpp"

namespace vb {

std::vector<double> ForwardSolution::change_m() const {
  std::vector<double> d(to_m);
  for (std::size_t i = 0; i < d.size() && i < from_m.size(); ++i) d[i] -= from_m[i];
  return d;
}

ForwardModel::ForwardModel(const Scene& scene, const Lattice& lattice, const FitRegions& regions, const FitSpec& fit,
                           const ClContext& cl)
    : scene_(scene), lattice_(lattice), regions_(regions), fit_(fit), cl_(cl) {
  require(scene.gravity.active, "a fit needs the observed posture's gravity", "gravity",
          "add [gravity] posture = \"prone\" (or the posture of the observation)");
  require(scene.indenters.empty() && scene.tori.empty(), "a fit models gravity only", "indenter, device.torus",
          "remove them from the fit's scene");
  if (scene_.solver.integrator != Integrator::Relaxation) {
    scene_.solver.integrator = Integrator::Relaxation;
    scene_.solver.dt_safety = 0.9;  // the scene parser's relaxation default
  }
  scene_.stop.equilibrium =
      fit.equilibrium > 0 ? fit.equilibrium : scene.solver.precision == Precision::Double ? 1e-7 : 1e-5;
  scene_.stop.max_steps = fit.max_steps;
  scene_.stop.max_time_s = INFINITY;
  unloaded_ = use_unloaded_reference(scene, fit);

  base_modulus_.resize(lattice.element_count());
  for (std::size_t e = 0; e < base_modulus_.size(); ++e) {
    const std::string& t = lattice.tissue_names[lattice.tissue_of_element[e]];
    const MaterialSpec& m = scene_.materials.at(t);
    base_modulus_[e] = regions.region_of_element[e] >= 0 ? material_modulus_pa(m) : m.youngs_modulus_pa;
  }
  split_ = fit.regions != FitSpec::Regions::Elements;
  if (!split_) {
    base_ = make_element_arrays(scene_, lattice);
    require(!base_.hyperelastic, "per-element regions need linear or biphasic springs", "fit.regions",
            "fit hyperelastic tissues by labels or blocks");
    return;
  }
  // One tissue per (tissue, region): its material row carries the region's modulus.
  split_lattice_ = lattice;
  split_lattice_.tissue_names.clear();
  std::map<std::pair<int, std::int32_t>, std::uint8_t> id;
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    const int t = lattice.tissue_of_element[e];
    const std::int32_t r = regions.region_of_element[e];
    auto it = id.find({t, r});
    if (it == id.end()) {
      require(id.size() < 255, "more than 255 (tissue, region) pairs", "fit.regions",
              "use larger blocks, fewer fitted tissues, or regions = \"elements\" with linear springs");
      const std::string name = lattice.tissue_names[std::size_t(t)] + (r >= 0 ? "#" + regions.names[std::size_t(r)] : "");
      it = id.emplace(std::make_pair(t, r), std::uint8_t(split_lattice_.tissue_names.size())).first;
      split_lattice_.tissue_names.push_back(name);
      split_origin_.emplace_back(r, lattice.tissue_names[std::size_t(t)]);
      MaterialSpec m = scene_.materials.at(lattice.tissue_names[std::size_t(t)]);
      m.name = name;
      scene_.materials[name] = m;
    }
    split_lattice_.tissue_of_element[e] = it->second;
  }
}

ForwardModel::~ForwardModel() = default;

ElementArrays ForwardModel::arrays(const std::vector<double>& E) const {
  require(E.size() == regions_.size(), "one modulus per region expected", "fit");
  if (split_) {
    for (std::size_t t = 0; t < split_origin_.size(); ++t) {
      const std::int32_t r = split_origin_[t].first;
      if (r < 0) continue;
      // hyperelastic laws scale all their constants (docs/FIT.md, "Hyperelastic tissues")
      MaterialSpec m = material_with_modulus(scene_.materials.at(split_origin_[t].second), E[std::size_t(r)]);
      m.name = split_lattice_.tissue_names[t];
      scene_.materials[m.name] = std::move(m);
    }
    return make_element_arrays(scene_, split_lattice_);
  }
  ElementArrays el = base_;
  for (std::size_t e = 0; e < el.youngs_modulus_pa.size(); ++e) {
    const std::int32_t r = regions_.region_of_element[e];
    if (r < 0) continue;
    const double scale = E[std::size_t(r)] / base_modulus_[e];
    el.youngs_modulus_pa[e] *= scale;
    el.stability_modulus_pa[e] *= scale;  // linear in E for linear and biphasic springs
  }
  return el;
}

std::vector<double> ForwardModel::element_modulus(const std::vector<double>& E) const {
  std::vector<double> out(base_modulus_);
  for (std::size_t e = 0; e < out.size(); ++e)
    if (regions_.region_of_element[e] >= 0) out[e] = E[std::size_t(regions_.region_of_element[e])];
  return out;
}

ForwardSolution ForwardModel::solve(const std::vector<double>& E, const ForwardSolution* warm) const {
  return solve_timed(E, warm, nullptr);
}

ForwardSolution ForwardModel::solve_timed(const std::vector<double>& E, const ForwardSolution* warm,
                                          JacobianTiming* timing) const {
  PhaseLaps lap(timing);
  const ElementArrays el = arrays(E);
  const Lattice& lat = lattice();
  ++solves_;
  if (unloaded_) {
    if (!reference_sims_) reference_sims_ = std::make_unique<UnloadedReferenceSimulators>();
    lap(&JacobianTiming::setup_s);
    ForwardSolution out = solve_from_unloaded_reference(scene_, lat, el, cl_, warm, *reference_sims_, timing);
    reference_solves_ += std::size_t(out.reference_solves);
    return out;
  }
  const bool build = !sim_;
  if (build) sim_ = std::make_unique<Simulator>(scene_, lat, el, cl_);
  else sim_->set_materials(el);  // as a simulator built with el starts
  Simulator& sim = *sim_;
  const std::size_t n = lat.element_count();
  const std::vector<double> zeros(3 * n, 0.0);
  const EquilibriumScales scales = equilibrium_scales(lat, el);
  lap(&JacobianTiming::setup_s);
  ForwardSolution out;
  out.from_m = zeros;
  std::vector<double> v;
  if (fit_.from_gravity_m_s2) {
    if (warm) sim.upload(warm->from_m, zeros);
    lap(&JacobianTiming::upload_s);
    out.steps += relax_to_equilibrium(sim, scene_, scales, *fit_.from_gravity_m_s2, "from");
    lap(&JacobianTiming::relax_s);
    sim.download(out.from_m, v);
    lap(&JacobianTiming::readback_s);
  }
  if (warm) sim.upload(warm->to_m, zeros);
  else if (fit_.from_gravity_m_s2) sim.upload(out.from_m, zeros);
  lap(&JacobianTiming::upload_s);
  out.steps += relax_to_equilibrium(sim, scene_, scales, scene_.gravity.acceleration_m_s2, "to");
  lap(&JacobianTiming::relax_s);
  sim.download(out.to_m, v);
  lap(&JacobianTiming::readback_s);
  if (timing) timing->add_solve(out.steps, n, build);
  return out;
}

}  // namespace vb
