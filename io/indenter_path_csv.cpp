#include "io/indenter_path_csv.hpp"

#include "engine/error.hpp"
#include "io/numeric_csv.hpp"

namespace vb {

std::vector<PathKnot> read_indenter_path_csv(const std::string& path) {
  // The file format (header, finite numbers, file:line errors) is read_numeric_csv's; the knots
  // add the trajectory's own rules.
  const std::vector<std::vector<double>> rows = read_numeric_csv(path, {"time_s", "x_mm", "y_mm", "z_mm"});
  std::vector<PathKnot> knots;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const std::vector<double>& v = rows[r];
    const std::string where = path + " (row " + std::to_string(r + 1) + ")";
    require(v[0] >= 0, "times must be >= 0 s", where);
    if (!knots.empty() && !(v[0] > knots.back().time_s))
      throw Error("times must increase strictly, got " + std::to_string(v[0]) + " s after " +
                      std::to_string(knots.back().time_s) + " s",
                  where);
    knots.push_back({v[0], 1e-3 * Vec3(v[1], v[2], v[3])});
  }
  require(knots.size() >= 2, "the trajectory has " + std::to_string(knots.size()) + " rows", path,
          "give at least two rows after the header time_s,x_mm,y_mm,z_mm");
  return knots;
}

}  // namespace vb
