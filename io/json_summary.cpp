#include "io/json_summary.hpp"

#include <cmath>

#include "io/atomic_file.hpp"
#include "voxbreast/config.hpp"

namespace vb {
namespace {

using nlohmann::json;

/// JSON has no NaN/Inf; a diverged run must still produce a parseable summary.
json number(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

json vec3(const Eigen::Vector3d& v) {
  return json::array({number(v.x()), number(v.y()), number(v.z())});
}

json tracked_to_json(const std::vector<TrackedPointResult>& tracked) {
  json out = json::object();
  for (const auto& t : tracked)
    out[t.name] = {{"point_m", vec3(t.point_m)},
                   {"rest_position_m", vec3(t.rest_m)},
                   {"displacement_m", vec3(t.displacement_m)},
                   {"displacement_norm_m", number(t.displacement_m.norm())},
                   {"element", t.element}};
  return out;
}

json indenters_to_json(const std::vector<IndenterResult>& indenters) {
  json out = json::array();
  for (const auto& d : indenters)
    out.push_back({{"position_m", vec3(d.position_m)},
                   {"reaction_force_n", vec3(d.reaction_force_n)},
                   {"reaction_force_norm_n", number(d.reaction_force_n.norm())},
                   {"contact_elements", d.contact_elements}});
  return out;
}

json tori_to_json(const std::vector<TorusResult>& tori) {
  json out = json::array();
  for (const auto& t : tori)
    out.push_back({{"name", t.name},
                   {"minor_radius_m", number(t.minor_radius_m)},
                   {"major_radius_m", number(t.major_radius_m)},
                   {"force_n", vec3(t.force_n)},
                   {"force_norm_n", number(t.force_n.norm())},
                   {"normal_force_sum_n", number(t.normal_force_sum_n)},
                   {"contact_elements", t.contact_elements},
                   {"contact_area_m2", number(t.contact_area_m2)},
                   {"peak_pressure_pa", number(t.peak_pressure_pa)},
                   {"mean_pressure_pa", number(t.mean_pressure_pa)},
                   {"max_penetration_m", number(t.max_penetration_m)},
                   {"max_penetration_during_run_m", number(t.max_penetration_run_m)}});
  return out;
}

json optional_number(const std::optional<double>& x) { return x ? number(*x) : json(nullptr); }

}  // namespace

json model_mass_to_json(const Lattice& lattice, const std::vector<TissueMass>& masses) {
  json tissues = json::object();
  double model = 0, voxels = 0, hull = 0, model_v = 0, voxels_v = 0, hull_v = 0;
  for (std::size_t t = 0; t < masses.size(); ++t) {
    const TissueMass& m = masses[t];
    const double rho = m.density_kg_m3;
    tissues[lattice.tissue_names[t]] = {{"body", m.hull_body ? "hull" : "voxels"},
                                        {"elements", m.elements},
                                        {"mass_kg", number(m.model_kg)},
                                        {"voxel_mass_kg", number(m.voxel_kg)},
                                        {"hull_mass_kg", number(m.hull_kg)},
                                        {"volume_m3", number(m.model_kg / rho)},
                                        {"voxel_volume_m3", number(m.voxel_kg / rho)},
                                        {"hull_volume_m3", number(m.hull_kg / rho)},
                                        {"floored_elements", m.floored}};
    model += m.model_kg, voxels += m.voxel_kg, hull += m.hull_kg;
    model_v += m.model_kg / rho, voxels_v += m.voxel_kg / rho, hull_v += m.hull_kg / rho;
  }
  return {{"total_mass_kg", number(model)},   {"voxel_mass_kg", number(voxels)},
          {"hull_mass_kg", number(hull)},     {"volume_m3", number(model_v)},
          {"voxel_volume_m3", number(voxels_v)}, {"hull_volume_m3", number(hull_v)},
          {"tissues", tissues}};
}

json positioning_to_json(const PositioningMetrics& m) {
  json out = {{"volume_change_fraction", number(m.volume_change)},
              {"surface_volume_change_fraction", number(m.surface_volume_change)},
              {"comfort",
               {{"peak_equivalent_strain", number(m.comfort.peak_equivalent_strain)},
                {"p95_equivalent_strain", number(m.comfort.p95_equivalent_strain)},
                {"peak_von_mises_stress_pa", number(m.comfort.peak_von_mises_pa)},
                {"p95_von_mises_stress_pa", number(m.comfort.p95_von_mises_pa)}}},
              {"tumour", nullptr},
              {"chest_wall", nullptr}};
  if (const auto& t = m.tumour) {
    out["tumour"] = {{"tissue", t->tissue},
                     {"elements", t->elements},
                     {"rest_centroid_m", vec3(t->rest_centroid_m)},
                     {"final_centroid_m", vec3(t->final_centroid_m)},
                     {"displacement_m", vec3(t->displacement_m())},
                     {"displacement_norm_m", number(t->displacement_m().norm())},
                     {"target_m", t->target_m ? vec3(*t->target_m) : json(nullptr)},
                     {"rest_target_distance_m", t->target_m ? number(t->rest_target_distance_m) : json(nullptr)},
                     {"final_target_distance_m", t->target_m ? number(t->final_target_distance_m) : json(nullptr)}};
  }
  if (const auto& c = m.chest_wall) {
    out["chest_wall"] = {{"anchor", c->anchor},
                         {"tumour_distance_rest_m", optional_number(c->tumour_rest_m)},
                         {"tumour_distance_final_m", optional_number(c->tumour_final_m)},
                         {"mean_distance_rest_m", number(c->mean_rest_m)},
                         {"mean_distance_final_m", number(c->mean_final_m)},
                         {"max_distance_rest_m", number(c->max_rest_m)},
                         {"max_distance_final_m", number(c->max_final_m)}};
  }
  return out;
}

json spread_to_json(const TumourSpread& s) {
  return {{"runs", s.runs},
          {"mean_m", vec3(s.mean_m)},
          {"std_axis_m", vec3(s.std_axis_m)},
          {"std_m", number(s.std_m)},
          {"max_m", number(s.max_m)}};
}

json reproducibility_to_json(const ReproducibilityResult& r, const ReproducibilitySpec& spec) {
  json runs = json::array();
  for (const PerturbedRun& run : r.runs)
    runs.push_back({{"index", run.index},
                    {"device", run.device},
                    {"rpy_deg", vec3(run.rpy_deg)},
                    {"tumour_centroid_m", vec3(run.tumour_centroid_m)},
                    {"converged", run.converged},
                    {"steps", run.steps}});
  return {{"perturbations", spec.perturbations},
          {"max_angle_deg", spec.max_angle_deg},
          {"seed", spec.seed},
          {"with_device", r.with_device ? spread_to_json(*r.with_device) : json(nullptr)},
          {"without_device", spread_to_json(r.without_device)},
          {"runs", runs}};
}

json reference_state_to_json(const ReferenceState& r, const ReferenceStateSpec& spec) {
  json history = json::array();
  for (const ReferenceIteration& it : r.history)
    history.push_back({{"iteration", it.iteration},
                       {"residual_max_m", number(it.residual_max_m)},
                       {"residual_rms_m", number(it.residual_rms_m)},
                       {"step", number(it.step)},
                       {"steps", it.steps}});
  return {{"ct_posture", spec.ct_posture.empty() ? json(nullptr) : json(spec.ct_posture)},
          {"ct_gravity_m_s2", vec3(spec.ct_gravity_m_s2)},
          {"tolerance_m", number(spec.tolerance_m)},
          {"converged", r.converged},
          {"iterations", r.history.size()},
          {"residual_max_m", number(r.residual_max_m)},
          {"residual_rms_m", number(r.residual_rms_m)},
          {"max_rest_offset_m", number(r.max_rest_offset_m)},
          {"unsupported_elements", r.unsupported_elements},
          {"steps", r.steps},
          {"wall_time_s", number(r.wall_time_s)},
          {"history", history}};
}

json summary_to_json(const RunSummary& s, const Scene& scene) {
  return {
      {"version", config::version},
      {"git_commit", config::git_commit},
      {"scene", scene.source_path},
      {"elements", s.elements},
      {"connections", s.connections},
      {"fixed_elements", s.fixed_elements},
      {"steps", s.steps},
      {"dt_s", number(s.dt_s)},
      {"dt_auto", s.dt_auto},
      {"simulated_time_s", number(s.simulated_time_s)},
      {"wall_time_s", number(s.wall_time_s)},
      {"steps_per_second", number(s.steps_per_second)},
      {"converged", s.converged},
      {"stop_reason", s.stop_reason},
      {"unconverged_reason", s.unconverged_reason.empty() ? nlohmann::json() : nlohmann::json(s.unconverged_reason)},
      {"final_residual", number(s.final_residual)},
      {"final_speed_ratio", number(s.final_speed_ratio)},
      {"max_displacement_m", number(s.max_displacement_m)},
      {"volume_change_fraction", number(s.volume_change)},
      {"surface_volume_change_fraction", number(s.surface_volume_change)},
      {"device", {{"name", s.device_name}, {"precision", s.precision}}},
      {"integrator", s.integrator},
      {"tracked", tracked_to_json(s.tracked)},
      {"indenters", indenters_to_json(s.indenters)},
      {"immobilisation_device", {{"tori", tori_to_json(s.tori)}}},
  };
}

void write_summary_json(const std::string& path, const RunSummary& summary, const Scene& scene) {
  // Replace invalid UTF-8 (e.g. an odd device name or path) instead of throwing mid-output.
  const std::string text = summary_to_json(summary, scene)
                               .dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  write_text_atomically(path, text + "\n");
}

}  // namespace vb
