#include "io/metrics_csv.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "io/atomic_file.hpp"

namespace vb {
namespace {

constexpr double kMm = 1e3, kMm2 = 1e6;

std::string number(double x) {
  if (!std::isfinite(x)) return "";
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", x);
  return text;
}

std::string number(const std::optional<double>& x) { return x ? number(*x) : ""; }

/// CSV field: quoted when it holds a separator, quote or line break.
std::string field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

}  // namespace

std::vector<std::pair<std::string, std::string>> metrics_row(const RunSummary& s, const PositioningMetrics& m) {
  std::vector<std::pair<std::string, std::string>> row;
  const auto add = [&](const std::string& name, const std::string& value) { row.emplace_back(name, value); };
  add("converged", s.converged ? "1" : "0");
  add("stop_reason", s.stop_reason);
  add("steps", std::to_string(s.steps));
  add("simulated_time_s", number(s.simulated_time_s));
  add("wall_time_s", number(s.wall_time_s));
  add("final_residual", number(s.final_residual));
  add("max_displacement_mm", number(kMm * s.max_displacement_m));
  add("volume_change_fraction", number(m.volume_change));
  add("surface_volume_change_fraction", number(m.surface_volume_change));

  const auto& t = m.tumour;
  const char* axes[] = {"x", "y", "z"};
  for (int c = 0; c < 3; ++c)
    add(std::string("tumour_rest_") + axes[c] + "_mm", t ? number(kMm * t->rest_centroid_m[c]) : "");
  for (int c = 0; c < 3; ++c)
    add(std::string("tumour_final_") + axes[c] + "_mm", t ? number(kMm * t->final_centroid_m[c]) : "");
  for (int c = 0; c < 3; ++c)
    add(std::string("tumour_d") + axes[c] + "_mm", t ? number(kMm * t->displacement_m()[c]) : "");
  add("tumour_displacement_mm", t ? number(kMm * t->displacement_m().norm()) : "");
  const bool target = t && t->target_m;
  add("tumour_target_distance_rest_mm", target ? number(kMm * t->rest_target_distance_m) : "");
  add("tumour_target_distance_mm", target ? number(kMm * t->final_target_distance_m) : "");

  const auto& c = m.chest_wall;
  const auto mm = [](const std::optional<double>& x) { return x ? std::optional<double>(kMm * *x) : std::nullopt; };
  add("tumour_chest_wall_distance_rest_mm", c ? number(mm(c->tumour_rest_m)) : "");
  add("tumour_chest_wall_distance_mm", c ? number(mm(c->tumour_final_m)) : "");
  add("breast_chest_wall_mean_distance_rest_mm", c ? number(kMm * c->mean_rest_m) : "");
  add("breast_chest_wall_mean_distance_mm", c ? number(kMm * c->mean_final_m) : "");
  add("breast_chest_wall_max_distance_rest_mm", c ? number(kMm * c->max_rest_m) : "");
  add("breast_chest_wall_max_distance_mm", c ? number(kMm * c->max_final_m) : "");

  if (const auto& r = m.reference_state) {  // scenes with [reference_state] only
    add("reference_state_iterations", std::to_string(r->iterations));
    add("reference_state_residual_max_mm", number(kMm * r->residual_max_m));
    add("reference_state_max_offset_mm", number(kMm * r->max_rest_offset_m));
  }
  if (const auto& r = m.reproducibility) {  // scenes with [reproducibility] only
    add("tumour_spread_std_device_mm", r->with_device ? number(kMm * r->with_device->std_m) : "");
    add("tumour_spread_max_device_mm", r->with_device ? number(kMm * r->with_device->max_m) : "");
    add("tumour_spread_std_no_device_mm", number(kMm * r->without_device.std_m));
    add("tumour_spread_max_no_device_mm", number(kMm * r->without_device.max_m));
  }
  add("peak_equivalent_strain", number(m.comfort.peak_equivalent_strain));
  add("p95_equivalent_strain", number(m.comfort.p95_equivalent_strain));
  add("peak_von_mises_stress_pa", number(m.comfort.peak_von_mises_pa));
  add("p95_von_mises_stress_pa", number(m.comfort.p95_von_mises_pa));

  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  double peak = 0, penetration = 0;
  for (const TorusResult& d : s.tori) {
    total += d.force_n;
    peak = std::max(peak, d.peak_pressure_pa);
    penetration = std::max(penetration, d.max_penetration_run_m);
  }
  if (!s.tori.empty()) {
    add("device_force_n", number(total.norm()));
    add("device_peak_pressure_pa", number(peak));
    add("device_max_penetration_mm", number(kMm * penetration));
  }
  for (const TorusResult& d : s.tori) {
    const std::string p = d.name + "_";
    add(p + "minor_radius_mm", number(kMm * d.minor_radius_m));
    add(p + "major_radius_mm", number(kMm * d.major_radius_m));
    for (int k = 0; k < 3; ++k) add(p + "force_" + axes[k] + "_n", number(d.force_n[k]));
    add(p + "force_n", number(d.force_n.norm()));
    add(p + "normal_force_sum_n", number(d.normal_force_sum_n));
    add(p + "contact_elements", std::to_string(d.contact_elements));
    add(p + "contact_area_mm2", number(kMm2 * d.contact_area_m2));
    add(p + "peak_pressure_pa", number(d.peak_pressure_pa));
    add(p + "mean_pressure_pa", number(d.mean_pressure_pa));
    add(p + "max_penetration_mm", number(kMm * d.max_penetration_run_m));
  }
  return row;
}

void write_metrics_csv(const std::string& path, const RunSummary& summary, const PositioningMetrics& metrics) {
  std::string header, values;
  const auto row = metrics_row(summary, metrics);
  for (std::size_t i = 0; i < row.size(); ++i) {
    header += (i ? "," : "") + field(row[i].first);
    values += (i ? "," : "") + field(row[i].second);
  }
  write_text_atomically(path, header + "\n" + values + "\n");
}

}  // namespace vb
