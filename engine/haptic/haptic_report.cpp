#include "engine/haptic/haptic_report.hpp"

#include <cstdio>

#include "io/csv_table.hpp"

namespace vb {

std::string haptic_log_csv(const HapticLoopResult& r) {
  std::string text = csv_line({"time_s", "x_mm", "y_mm", "z_mm", "fx_n", "fy_n", "fz_n", "updates", "min_det_f"});
  for (const HapticSample& s : r.samples) {
    const auto n = [](double x) { return shortest_number_text(x); };
    text += csv_line({n(s.time_s), n(1e3 * s.probe_m.x()), n(1e3 * s.probe_m.y()), n(1e3 * s.probe_m.z()),
                      n(s.force_n.x()), n(s.force_n.y()), n(s.force_n.z()), std::to_string(s.updates),
                      n(s.min_det_f)});
  }
  return text;
}

std::string haptic_fold_warning(const HapticLoopResult& r) {
  if (!r.folded) return {};
  char text[400];
  std::snprintf(text, sizeof text,
                "the lattice folded under the probe at t = %.3f s (min det F %.3g): the force is not the "
                "tissue's; press less deep or refine the spacing",
                r.first_fold_time_s, r.min_det_f);
  return text;
}

nlohmann::json haptic_summary_json(const HapticLoopResult& r, const HapticLoopOptions& o, const HapticProbe& probe,
                                   std::size_t elements) {
  const Simulator& sim = probe.simulator();
  const HapticUpdate last = probe.last_update();
  const double ms = 1e3;
  nlohmann::json j = {
      {"target_rate_hz", o.rate_hz},
      {"achieved_rate_hz", r.achieved_rate_hz},
      {"outputs", r.samples.size()},
      {"interval_mean_ms", ms * r.intervals.mean_s},
      {"interval_p50_ms", ms * r.intervals.p50_s},
      {"interval_p99_ms", ms * r.intervals.p99_s},
      {"interval_max_ms", ms * r.intervals.max_s},
      {"interval_stddev_ms", ms * r.intervals.stddev_s},
      {"missed_deadlines", r.intervals.missed},
      {"realtime_priority", r.realtime},
      {"wall_s", r.wall_s},
      {"deformation_updates", r.updates},
      {"update_rate_hz", r.update_rate_hz},
      {"steps", r.steps},
      {"steps_per_update", r.updates > 0 ? double(r.steps) / double(r.updates) : 0.0},
      {"steps_per_second", r.wall_s > 0 ? double(r.steps) / r.wall_s : 0.0},
      {"elements", elements},
      {"dt_s", sim.dt_s()},
      {"device", sim.context().info.name},
      {"precision", sim.precision() == Precision::Double ? "double" : "float"},
      {"blown_up", r.blown_up},
      {"message", r.message},
      {"final_force_n", {last.force_n.x(), last.force_n.y(), last.force_n.z()}},
      {"final_probe_mm", {1e3 * last.probe_m.x(), 1e3 * last.probe_m.y(), 1e3 * last.probe_m.z()}},
      {"final_residual", last.residual},
      {"final_contact_elements", last.contact_elements},
      {"folded", r.folded},
      {"min_det_f", r.min_det_f},
      {"final_min_det_f", last.min_det_f},
      {"final_inverted_elements", last.inverted_elements},
      {"first_fold_time_s", r.folded ? nlohmann::json(r.first_fold_time_s) : nlohmann::json(nullptr)},
      {"first_fold_update", r.folded ? nlohmann::json(r.first_fold_update) : nlohmann::json(nullptr)},
      {"fold_checks", r.fold_checks},
      {"folded_checks", r.folded_checks},
      {"fold_check_wall_s", r.fold_check_wall_s},
  };
  return j;
}

}  // namespace vb
