#pragma once
/// One modulus per region for every law (docs/FIT.md, "Hyperelastic tissues"): a hyperelastic
/// law is fitted by a scale of all its constants, which keeps its shape.
#include "engine/scene/scene.hpp"

namespace vb {

/// The material with small-strain Young's modulus E (Pa). Linear and biphasic springs: E itself.
/// Hyperelastic laws: every shear constant (neo-Hookean μ through E; Mooney-Rivlin C10, C01;
/// Ogden μ_p) and an explicit bulk modulus are scaled by E / material_modulus_pa(m), so the
/// law's shape (α_p, C01/C10, ν) is kept and its small-strain modulus becomes E.
MaterialSpec material_with_modulus(const MaterialSpec& m, double youngs_modulus_pa);

}  // namespace vb
