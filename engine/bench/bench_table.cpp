#include "engine/bench/bench_table.hpp"

#include <cmath>
#include <sstream>

#include "engine/bench/bench_knobs.hpp"

namespace vb::bench {
namespace {

/// (name, value) pairs of a row in column order; strings and numbers.
struct Field {
  const char* name;
  std::string text;  ///< for strings
  double number = 0;
  bool is_text = false;
};

std::vector<Field> fields(const CaseResult& r) {
  const BenchCase& c = r.knobs;
  const auto text = [](const char* n, const std::string& s) { return Field{n, s, 0, true}; };
  const auto num = [](const char* n, double x) { return Field{n, "", x, false}; };
  const double steps_per_s = r.seconds_per_step > 0 ? 1 / r.seconds_per_step : std::nan("");
  return {text("scene", c.scene),
          text("part", c.part),
          text("law", c.law),
          text("integrator", c.integrator),
          text("precision", precision_name(c.precision)),
          num("downsample", c.downsample),
          num("dt_factor", c.dt_factor),
          text("volume", c.volume ? "on" : "off"),
          num("tolerance", r.tolerance),
          text("status", r.status),
          num("elements", double(r.elements)),
          num("spacing_mm", 1e3 * r.spacing_m),
          num("dt_s", r.dt_s),
          num("auto_dt_s", r.auto_dt_s),
          num("steps", double(r.steps)),
          num("simulated_s", r.steps > 0 ? r.simulated_s : std::nan("")),
          num("wall_s", r.steps > 0 ? r.wall_s : std::nan("")),
          num("time_per_step_ms", r.seconds_per_step > 0 ? 1e3 * r.seconds_per_step : std::nan("")),
          num("steps_per_s", steps_per_s),
          num("ns_per_element_step", steps_per_s > 0 ? 1e9 / (steps_per_s * double(r.elements)) : std::nan("")),
          num("device_bytes_per_element", r.device_bytes_per_element > 0 ? r.device_bytes_per_element : std::nan("")),
          num("max_displacement_mm", 1e3 * r.max_displacement_m),
          num("error_max_mm", 1e3 * r.error_max_m),
          num("error_rms_mm", 1e3 * r.error_rms_m),
          num("track_error_mm", 1e3 * r.track_error_m),
          num("volume_change", r.volume_change),
          num("volume_error", r.volume_error),
          num("closed_form_error", r.closed_form_error),
          text("message", r.message)};
}

std::string csv_quoted(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char ch : s) {
    if (ch == '"') out += '"';
    out += ch == '\n' ? ' ' : ch;
  }
  return out + "\"";
}

}  // namespace

nlohmann::json row_json(const CaseResult& r) {
  nlohmann::json row = nlohmann::json::object();
  for (const Field& f : fields(r)) {
    if (f.is_text) row[f.name] = f.text;
    else if (std::isfinite(f.number)) row[f.name] = f.number;
    else row[f.name] = nullptr;
  }
  return row;
}

std::string csv_header() {
  std::string line;
  for (const Field& f : fields(CaseResult{})) line += (line.empty() ? "" : ",") + std::string(f.name);
  return line + "\n";
}

std::string csv_row(const CaseResult& r) {
  std::ostringstream line;
  line.precision(9);
  bool first = true;
  for (const Field& f : fields(r)) {
    if (!first) line << ",";
    first = false;
    if (f.is_text) line << csv_quoted(f.text);
    else if (std::isfinite(f.number)) line << f.number;
  }
  line << "\n";
  return line.str();
}

}  // namespace vb::bench
