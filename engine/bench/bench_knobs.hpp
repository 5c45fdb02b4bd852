#pragma once
/// The knobs of `voxbreast bench` by name: material law, integrator (or solver mode) and
/// precision, each a named change to a scene. A new integrator or solver mode is one line in
/// the table of bench_knobs.cpp.
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"

namespace vb::bench {

/// Integrator / solver-mode names, in table order ("symplectic_euler", "heun", ...).
std::vector<std::string> integrator_names();
/// Sets the scene's integrator or solver mode. Throws vb::Error for an unknown name.
void apply_integrator(Scene& scene, const std::string& name);

/// Law names: "linear", "biphasic", "neo-hookean", "ogden" (two-term).
std::vector<std::string> law_names();
/// Gives every deformable tissue the law, keeping its small-strain Young's modulus: biphasic
/// springs c3 = 20, εc = 0.1 (docs/VALIDATION.md); hyperelastic laws ν = 0.45 and μ₀ = E/(2(1+ν));
/// the Ogden law has the validation's shape (μ ∝ 1200, −300 Pa; α = 4, −2) scaled to that μ₀.
/// Rigid tissues are left alone. Throws vb::Error for an unknown name.
void apply_law(Scene& scene, const std::string& law);

const char* precision_name(Precision p);
Precision parse_precision(const std::string& name);

}  // namespace vb::bench
