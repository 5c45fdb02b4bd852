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

}  // namespace

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
      {"final_residual", number(s.final_residual)},
      {"final_speed_ratio", number(s.final_speed_ratio)},
      {"max_displacement_m", number(s.max_displacement_m)},
      {"volume_change_fraction", number(s.volume_change)},
      {"surface_volume_change_fraction", number(s.surface_volume_change)},
      {"device", {{"name", s.device_name}, {"precision", s.precision}}},
      {"integrator", s.integrator},
      {"tracked", tracked_to_json(s.tracked)},
      {"indenters", indenters_to_json(s.indenters)},
  };
}

void write_summary_json(const std::string& path, const RunSummary& summary, const Scene& scene) {
  // Replace invalid UTF-8 (e.g. an odd device name or path) instead of throwing mid-output.
  const std::string text = summary_to_json(summary, scene)
                               .dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  write_text_atomically(path, text + "\n");
}

}  // namespace vb
