#include "io/fit_landmarks_csv.hpp"

#include <fstream>
#include <sstream>

#include "engine/error.hpp"

namespace vb {
namespace {

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  std::string field;
  while (std::getline(s, field, ',')) {
    const auto b = field.find_first_not_of(" \t\r"), e = field.find_last_not_of(" \t\r");
    out.push_back(b == std::string::npos ? "" : field.substr(b, e - b + 1));
  }
  if (!line.empty() && line.back() == ',') out.emplace_back();  // getline drops a trailing empty field
  return out;
}

}  // namespace

std::vector<Landmark> read_fit_landmarks(const std::string& path) {
  std::ifstream in(path);
  require(bool(in), "cannot open the landmark file", path, "check fit.landmarks");
  std::string line;
  require(bool(std::getline(in, line)), "the landmark file is empty", path);
  const std::vector<std::string> head = split_fields(line);
  const std::vector<std::string> want = {"x_mm", "y_mm", "z_mm", "dx_mm", "dy_mm", "dz_mm"};
  require(head.size() >= 6 && std::equal(want.begin(), want.end(), head.begin()) &&
              (head.size() == 6 || (head.size() == 7 && head[6] == "sigma_mm")),
          "unexpected header '" + line + "'", path, "the header is x_mm,y_mm,z_mm,dx_mm,dy_mm,dz_mm[,sigma_mm]");
  std::vector<Landmark> out;
  int row = 1;
  while (std::getline(in, line)) {
    ++row;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<std::string> f = split_fields(line);
    const std::string where = path + " row " + std::to_string(row);
    require(f.size() == head.size(), "expected " + std::to_string(head.size()) + " fields", where);
    double v[7] = {0, 0, 0, 0, 0, 0, 0};
    for (std::size_t i = 0; i < f.size(); ++i) {
      std::size_t used = 0;
      try {
        v[i] = std::stod(f[i], &used);
      } catch (const std::exception&) {
        used = 0;
      }
      require(used == f[i].size() && used > 0, "'" + f[i] + "' is not a number (" + head[i] + ")", where);
    }
    Landmark l;
    l.point_m = Eigen::Vector3d(v[0], v[1], v[2]) * 1e-3;
    l.displacement_m = Eigen::Vector3d(v[3], v[4], v[5]) * 1e-3;
    l.sigma_m = v[6] * 1e-3;
    out.push_back(l);
  }
  require(!out.empty(), "the landmark file has no rows", path);
  return out;
}

}  // namespace vb
