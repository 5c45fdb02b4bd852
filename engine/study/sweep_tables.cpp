#include "engine/study/sweep_tables.hpp"

#include <fstream>
#include <map>

#include "engine/error.hpp"
#include "io/atomic_file.hpp"
#include "io/csv_table.hpp"

namespace vb {
namespace {

void flatten(const nlohmann::json& node, const std::string& path,
             std::vector<std::pair<std::string, nlohmann::json>>& out) {
  const auto child = [&](const std::string& key) { return path.empty() ? key : path + "." + key; };
  if (node.is_object()) {
    for (const auto& [key, value] : node.items()) flatten(value, child(key), out);
  } else if (node.is_array()) {
    for (std::size_t i = 0; i < node.size(); ++i) flatten(node[i], child(std::to_string(i + 1)), out);
  } else if (!node.is_string()) {
    out.emplace_back(path, node);
  }
}

/// Columns in order of first appearance, with each row's values by column.
struct Table {
  std::vector<std::string> columns;
  std::map<std::string, std::size_t> position;
  std::vector<std::map<std::size_t, std::string>> rows;

  void add(std::size_t row, const std::string& column, const std::string& text) {
    auto [it, inserted] = position.emplace(column, columns.size());
    if (inserted) columns.push_back(column);
    rows.at(row)[it->second] = text;
  }
  std::vector<std::string> row_fields(std::size_t row) const {
    std::vector<std::string> fields(columns.size());
    for (const auto& [column, text] : rows[row]) fields[column] = text;
    return fields;
  }
};

nlohmann::json read_summary(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return nlohmann::json::object();  // a case without summary.json has no metrics
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(std::string("not valid JSON: ") + e.what(), path, "remove this case folder to run the case again");
  }
}

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

}  // namespace

std::vector<std::pair<std::string, nlohmann::json>> flatten_scalars(const nlohmann::json& document) {
  std::vector<std::pair<std::string, nlohmann::json>> out;
  if (document.is_object() || document.is_array()) flatten(document, "", out);  // a bare scalar has no name
  return out;
}

bool is_timing_field(const std::string& path) {
  const std::string leaf = path.substr(path.rfind('.') + 1);
  const auto ends_with = [&](const std::string& tail) {
    return leaf.size() >= tail.size() && leaf.compare(leaf.size() - tail.size(), tail.size(), tail) == 0;
  };
  if (ends_with("wall_time_s") || leaf.find("per_second") != std::string::npos) return true;
  // a fit's jacobian_timing: this run's split of its perturbed solves (a resumed fit counts afresh);
  // a simulation's phase times and its image outputs' seconds and memory: this machine's, this run's
  for (const char* prefix : {"jacobian_timing.", "timings.", "image_outputs.step_seconds.",
                             "image_outputs.step_cpu_seconds.", "image_outputs.host_memory."})
    if (path.rfind(prefix, 0) == 0) return true;
  return false;
}

std::string scalar_text(const nlohmann::json& v) {
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  if (v.is_number_integer()) return v.is_number_unsigned() ? std::to_string(v.get<std::uint64_t>())
                                                           : std::to_string(v.get<std::int64_t>());
  if (v.is_number()) return shortest_number_text(v.get<double>());
  return {};
}

SweepTablesReport write_sweep_tables(const SweepFolder& folder, const SweepGrid& grid) {
  SweepTablesReport report;
  std::vector<std::string> fixed = {"case"};
  for (const SweepParameter& p : grid.parameters()) fixed.push_back(p.key);
  fixed.insert(fixed.end(), {"status", "error"});
  Table metrics, timing;
  metrics.rows.resize(grid.size());
  timing.rows.resize(grid.size());
  std::string metrics_csv, timing_csv;
  std::vector<std::vector<std::string>> fixed_rows, timing_rows;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    std::vector<std::string> row = {folder.case_id(i)};
    for (const std::string& v : grid.values_of(i)) row.push_back(toml_value_plain(v));
    if (!folder.is_finished(i)) {
      ++report.pending;
      row.insert(row.end(), {"pending", ""});
      fixed_rows.push_back(row);
      timing_rows.push_back({folder.case_id(i), "pending", "", "", "", ""});
      continue;
    }
    const SweepCaseRecord r = folder.read_record(i);
    (r.status == "ok" ? report.ok : report.failed)++;
    row.insert(row.end(), {r.status, r.error});
    fixed_rows.push_back(row);
    timing_rows.push_back({folder.case_id(i), r.status, std::to_string(r.rank), std::to_string(r.worker), r.device,
                           shortest_number_text(r.wall_time_s)});
    if (r.status != "ok") continue;
    for (const auto& [path, value] : flatten_scalars(read_summary(folder.case_dir(i) + "/summary.json")))
      (is_timing_field(path) ? timing : metrics).add(i, path, scalar_text(value));
  }
  metrics_csv = csv_line(concat(fixed, metrics.columns));
  timing_csv = csv_line(concat({"case", "status", "rank", "worker", "device", "case_wall_time_s"}, timing.columns));
  for (std::size_t i = 0; i < grid.size(); ++i) {
    metrics_csv += csv_line(concat(fixed_rows[i], metrics.row_fields(i)));
    timing_csv += csv_line(concat(timing_rows[i], timing.row_fields(i)));
  }
  write_text_atomically(folder.path("metrics.csv"), metrics_csv);
  write_text_atomically(folder.path("timing.csv"), timing_csv);
  return report;
}

}  // namespace vb
