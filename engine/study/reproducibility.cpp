#include "engine/study/reproducibility.hpp"

#include <random>

#include "engine/error.hpp"
#include "engine/sim/run.hpp"
#include "engine/study/positioning_metrics.hpp"

namespace vb {
std::vector<Vec3> perturbation_angles_deg(const ReproducibilitySpec& spec) {
  std::mt19937_64 bits(spec.seed);
  // [0, 1) from the top 53 bits: distributions are implementation-defined, the engine is not.
  const auto uniform = [&] { return double(bits() >> 11) * 0x1.0p-53; };
  std::vector<Vec3> angles(std::size_t(spec.perturbations));
  for (Vec3& a : angles)
    for (int c = 0; c < 3; ++c) a[c] = spec.max_angle_deg * (2 * uniform() - 1);
  return angles;
}

TumourSpread tumour_spread(const std::vector<Vec3>& p) {
  TumourSpread s;
  s.runs = int(p.size());
  if (p.empty()) return s;
  for (const Vec3& x : p) s.mean_m += x;
  s.mean_m /= double(p.size());
  Vec3 var = Vec3::Zero();
  for (const Vec3& x : p) {
    const Vec3 d = x - s.mean_m;
    var += d.cwiseProduct(d);
    s.max_m = std::max(s.max_m, d.norm());
  }
  var /= double(p.size());
  s.std_axis_m = var.cwiseSqrt();
  s.std_m = std::sqrt(var.sum());
  return s;
}

std::optional<std::string> unsettled_runs_warning(const ReproducibilityResult& r) {
  std::string names;
  int unsettled = 0;
  for (const PerturbedRun& run : r.runs) {
    if (run.converged) continue;
    names += std::string(unsettled++ ? ", " : "") + "posture " + std::to_string(run.index) +
             (run.device ? " with the device" : " without it");
  }
  if (unsettled == 0) return std::nullopt;
  return std::to_string(unsettled) + " of " + std::to_string(r.runs.size()) +
         " perturbed runs stopped before equilibrium (" + names +
         "), and the tumour spreads count them where they stopped: raise stop.max_steps, or see the "
         "converged column of reproducibility.csv";
}

ReproducibilityResult run_reproducibility(const Scene& scene, const Lattice& lattice, const ClContext& cl,
                                          const std::vector<double>* rest_offsets_m,
                                          const std::function<void(const PerturbedRun&)>& on_run,
                                          const std::function<void(const RunProgress&)>& on_step) {
  const std::string where = "reproducibility (line " + std::to_string(scene.reproducibility.line) + ")";
  const AnchorSpec* wall = chest_wall_anchor(scene);
  require(wall && wall->kind == AnchorSpec::Kind::Sphere, "the chest wall to perturb is not a sphere anchor", where,
          "name a sphere anchor in [positioning] chest_wall (docs/POSITIONING.md)");
  const std::size_t wall_index = std::size_t(wall - scene.anchors.data());
  const std::vector<Vec3> angles = perturbation_angles_deg(scene.reproducibility);

  ReproducibilityResult out;
  std::vector<Vec3> with, without;
  for (const bool device : {true, false}) {
    if (device && scene.tori.empty()) continue;
    Scene config = scene;
    if (!device) config.tori.clear();  // nothing of the device is built (kernels or buffers)
    config.reproducibility = ReproducibilitySpec{};
    config.output.frames_every = 0;
    const ElementArrays base = make_element_arrays(config, lattice);
    Simulator sim(config, lattice, base, cl);
    if (rest_offsets_m) sim.set_rest_offsets(*rest_offsets_m);
    const std::vector<double> at_rest(3 * lattice.element_count(), 0.0);
    for (std::size_t k = 0; k < angles.size(); ++k) {
      Scene posed = config;
      posed.anchors[wall_index].rpy_deg += angles[k];
      const ElementArrays el = make_element_arrays(posed, lattice);  // the held elements' new pose
      sim.upload(el.displacement_m, at_rest);  // the patient turned with the chest wall
      sim.restart_clock();
      // The patient turns under the fixed device, so the rings may start in the skin: the first
      // steps push it out, which is the device holding the breast.
      const RunOutput run = run_simulation(posed, lattice, el, sim, on_step, /*refuse_penetrating_start=*/false);
      const PositioningMetrics m = compute_positioning_metrics(posed, lattice, el, run.summary, run.state);
      require(m.tumour.has_value(), "the scene has no tumour tissue to follow", where,
              "set [positioning] tumour_tissue to the tissue to follow");
      PerturbedRun r;
      r.index = int(k) + 1;
      r.device = device;
      r.rpy_deg = posed.anchors[wall_index].rpy_deg;
      r.tumour_centroid_m = m.tumour->final_centroid_m;
      r.converged = run.summary.converged;
      r.steps = run.summary.steps;
      (device ? with : without).push_back(r.tumour_centroid_m);
      out.runs.push_back(r);
      if (on_run) on_run(r);
    }
  }
  if (!scene.tori.empty()) out.with_device = tumour_spread(with);
  out.without_device = tumour_spread(without);
  return out;
}

}  // namespace vb
