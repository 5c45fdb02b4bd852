#include "io/indenter_path_csv.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include "engine/error.hpp"

namespace vb {
namespace {

std::string trimmed(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string f;
  while (std::getline(ss, f, ',')) out.push_back(trimmed(f));
  return out;
}

}  // namespace

std::vector<PathKnot> read_indenter_path_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot open the indenter trajectory", path, "check the path (relative to the scene file)");
  const std::string want = "time_s,x_mm,y_mm,z_mm";
  std::string line;
  int number = 0;
  std::vector<PathKnot> knots;
  bool header = false;
  while (std::getline(in, line)) {
    ++number;
    const std::string where = path + ":" + std::to_string(number);
    if (trimmed(line).empty() || trimmed(line)[0] == '#') continue;
    const std::vector<std::string> f = fields(line);
    if (!header) {
      std::string joined;
      for (const std::string& x : f) joined += (joined.empty() ? "" : ",") + x;
      if (joined != want) throw Error("the trajectory's header is '" + joined + "'", where, "it must be " + want);
      header = true;
      continue;
    }
    if (f.size() != 4) throw Error("expected 4 numbers, got " + std::to_string(f.size()) + " fields", where);
    double v[4];
    for (int k = 0; k < 4; ++k) {
      std::size_t used = 0;
      try {
        v[k] = std::stod(f[k], &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != f[k].size() || f[k].empty() || !std::isfinite(v[k]))
        throw Error("field " + std::to_string(k + 1) + " ('" + f[k] + "') is not a finite number", where);
    }
    if (!knots.empty() && !(v[0] > knots.back().time_s))
      throw Error("times must increase strictly, got " + f[0] + " s after " + std::to_string(knots.back().time_s) + " s",
                  where);
    if (v[0] < 0) throw Error("times must be >= 0 s", where);
    knots.push_back({v[0], 1e-3 * Vec3(v[1], v[2], v[3])});
  }
  if (knots.size() < 2)
    throw Error("the trajectory has " + std::to_string(knots.size()) + " rows", path, "give at least two rows after the header " + want);
  return knots;
}

}  // namespace vb
