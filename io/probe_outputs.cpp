#include "io/probe_outputs.hpp"

#include <nlohmann/json.hpp>

#include <cmath>

#include "io/atomic_file.hpp"
#include "io/csv_table.hpp"

namespace vb {
namespace {

std::string num(double x) { return shortest_number_text(x); }
std::string mm(double x) { return shortest_number_text(1e3 * x); }

std::string force_label(double f) { return "depth_at_" + num(f) + "N_mm"; }

}  // namespace

void write_probe_outputs(const std::string& dir, const Scene& scene, const ProbeResult& r) {
  std::string curves = csv_line({"press", "position_mm", "depth_mm", "press_force_n", "fx_n", "fy_n", "fz_n",
                                 "contact_elements", "contact_area_mm2", "steps", "residual", "converged",
                                 "min_det_f", "inverted_elements"});
  std::vector<std::string> head = {"press", "position_mm", "x_mm", "y_mm", "z_mm", "peak_force_n", "stiffness_n_per_mm",
                                   "contact_area_mm2", "min_det_f", "inverted"};
  for (double f : scene.probe.at_force_n) head.push_back(force_label(f));
  std::string profile = csv_line(head);
  nlohmann::json presses = nlohmann::json::array();
  for (std::size_t k = 0; k < r.presses.size(); ++k) {
    const PressResult& p = r.presses[k];
    for (const PressSample& s : p.samples)
      curves += csv_line({std::to_string(k + 1), mm(p.position_m), mm(s.depth_m), num(s.press_force_n), num(s.force_n.x()),
                          num(s.force_n.y()), num(s.force_n.z()), std::to_string(s.contact_elements),
                          num(1e6 * s.contact_area_m2), std::to_string(s.steps), num(s.residual),
                          s.converged ? "1" : "0", num(s.min_det_f), std::to_string(s.inverted_elements)});
    std::vector<std::string> row = {std::to_string(k + 1), mm(p.position_m), mm(p.start_m.x()), mm(p.start_m.y()),
                                    mm(p.start_m.z()), num(p.peak_force_n), num(1e-3 * p.stiffness_n_m),
                                    num(1e6 * p.samples.back().contact_area_m2), num(p.min_det_f), p.inverted ? "1" : "0"};
    nlohmann::json at = nlohmann::json::object();
    for (std::size_t i = 0; i < p.depth_at_force_m.size(); ++i) {
      const double d = p.depth_at_force_m[i];
      row.push_back(std::isfinite(d) ? mm(d) : "");
      at[num(scene.probe.at_force_n[i])] = std::isfinite(d) ? nlohmann::json(1e3 * d) : nlohmann::json(nullptr);
    }
    profile += csv_line(row);
    const Vec3& F = p.samples.back().force_n;
    presses.push_back({{"start_mm", {1e3 * p.start_m.x(), 1e3 * p.start_m.y(), 1e3 * p.start_m.z()}},
                       {"position_mm", 1e3 * p.position_m},
                       {"peak_force_n", p.peak_force_n},
                       {"reaction_force_n", {F.x(), F.y(), F.z()}},
                       {"stiffness_n_per_mm", 1e-3 * p.stiffness_n_m},
                       {"contact_area_mm2", 1e6 * p.samples.back().contact_area_m2},
                       {"depth_at_force_mm", at},
                       {"min_det_f", p.min_det_f},
                       {"inverted", p.inverted}});
  }
  const nlohmann::json summary = {
      {"settle", {{"steps", r.settle_steps}, {"residual", r.settle_residual}, {"converged", r.settled},
                  {"max_displacement_mm", 1e3 * r.settle_max_displacement_m}}},
      {"depth_mm", 1e3 * scene.probe.depth_m},
      {"steps_per_press", scene.probe.steps},
      {"unconverged_increments", r.unconverged_increments},
      {"inverted_increments", r.inverted_increments},
      {"total_steps", r.total_steps},
      {"wall_time_s", r.wall_time_s},
      {"presses", presses}};
  write_text_atomically(dir + "/probe_curves.csv", curves);
  write_text_atomically(dir + "/probe_profile.csv", profile);
  write_text_atomically(dir + "/probe_summary.json", summary.dump(2) + "\n");
}

}  // namespace vb
