#pragma once
/// The material parameters a force-curve fit can tune, by name, with the unconstrained
/// coordinate the optimiser moves (so every trial value is admissible):
///   E                 Young's modulus (Pa)           log
///   cubic             biphasic c3 (> 0)              log
///   critical_strain   biphasic εc ∈ (0, 1)           logit
///   mu                one-term Ogden μ1 (Pa)         log|μ1|, sign kept
///   alpha             one-term Ogden α1              log|α1|, sign kept
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"

namespace vb {

/// The parameters a law tunes by default: biphasic E, cubic, critical_strain; ogden mu, alpha;
/// linear and neo-hookean E.
std::vector<std::string> default_fit_parameters(const MaterialSpec& material);

/// Throws vb::Error when `name` is unknown or does not apply to the material's law (or the
/// value there cannot be moved: c3 = 0, a multi-term Ogden).
void check_fit_parameter(const MaterialSpec& material, const std::string& name);

double parameter_value(const MaterialSpec& material, const std::string& name);
void set_parameter_value(MaterialSpec& material, const std::string& name, double value);

/// value ↔ unconstrained coordinate (see the table above); `like` gives the sign
double to_coordinate(const std::string& name, double value);
double from_coordinate(const std::string& name, double coordinate, double like);

}  // namespace vb
