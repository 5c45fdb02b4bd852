#include "engine/curve_fit/material_parameters.hpp"

#include <cmath>

#include "engine/error.hpp"

namespace vb {

std::vector<std::string> default_fit_parameters(const MaterialSpec& m) {
  if (m.law == "biphasic") return {"E", "cubic", "critical_strain"};
  if (m.law == "ogden") return {"mu", "alpha"};
  return {"E"};
}

void check_fit_parameter(const MaterialSpec& m, const std::string& name) {
  const std::string where = "materials." + m.name;
  if (name == "E") {
    require(m.law_takes_E(), "E is not a parameter of law '" + m.law + "'", where, "fit mu and alpha for ogden");
    require(m.youngs_modulus_pa > 0, "E must start positive", where);
  } else if (name == "cubic" || name == "critical_strain") {
    require(m.law == "biphasic", name + " is a parameter of biphasic springs, not of law '" + m.law + "'", where);
    require(name != "cubic" || m.cubic > 0, "cubic must start above 0 to be fitted (it moves in log scale)", where,
            "start from a small positive c3, e.g. 1");
  } else if (name == "mu" || name == "alpha") {
    require(m.law == "ogden", name + " is an Ogden parameter, not of law '" + m.law + "'", where);
    require(m.ogden_mu_pa.size() == 1, "mu and alpha are fitted for a one-term Ogden law only", where,
            "give mu and alpha one value each");
  } else {
    throw Error("unknown fit parameter '" + name + "'", "--params", "use E, cubic, critical_strain, mu or alpha");
  }
}

double parameter_value(const MaterialSpec& m, const std::string& name) {
  if (name == "E") return m.youngs_modulus_pa;
  if (name == "cubic") return m.cubic;
  if (name == "critical_strain") return m.critical_strain;
  if (name == "mu") return m.ogden_mu_pa.at(0);
  if (name == "alpha") return m.ogden_alpha.at(0);
  throw Error("unknown fit parameter '" + name + "'");
}

void set_parameter_value(MaterialSpec& m, const std::string& name, double value) {
  if (name == "E") m.youngs_modulus_pa = value;
  else if (name == "cubic") m.cubic = value;
  else if (name == "critical_strain") m.critical_strain = value;
  else if (name == "mu") m.ogden_mu_pa.at(0) = value;
  else if (name == "alpha") m.ogden_alpha.at(0) = value;
  else throw Error("unknown fit parameter '" + name + "'");
}

double to_coordinate(const std::string& name, double value) {
  if (name == "critical_strain") return std::log(value / (1 - value));
  return std::log(std::abs(value));
}

double from_coordinate(const std::string& name, double x, double like) {
  if (name == "critical_strain") return 1 / (1 + std::exp(-x));
  return std::copysign(std::exp(x), like);
}

}  // namespace vb
