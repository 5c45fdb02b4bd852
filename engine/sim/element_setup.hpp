#pragma once
/// Per-element physical arrays (double, SI) built from the scene and lattice; the simulator
/// uploads them in the chosen precision and the host reference uses them as they are.
#include <array>
#include <vector>

#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"

namespace vb {

struct ElementArrays {
  /// n, spring modulus: E for linear-spring tissues; 2.5·μ₀ for hyperelastic ones (the E of a
  /// ν = 1/4 lattice with their shear modulus, used by hourglass springs and dashpots)
  std::vector<double> youngs_modulus_pa;
  /// n, modulus setting the fastest wave for the time-step bound (Pa): E for springs (biphasic:
  /// E·(1 + 3·c3·εc²), the stiffest tangent); for hyperelastic tissues the P-wave modulus over
  /// the lattice's C11/E = 1.2, plus hourglass springs
  std::vector<double> stability_modulus_pa;
  std::vector<double> mass_kg;  ///< n, density × the element's share of its body (sim/element_mass.hpp)
  std::vector<double> inverse_mass;       ///< n, 1/kg; 0 for held elements
  std::vector<double> displacement_m;     ///< n×3 initial (prescribed for held elements)
  std::size_t held_count = 0;
  /// per tissue, the kernels' material table row (kernels/hyperelastic.cl: law, N, μ_p, α_p, κ;
  /// law 3, biphasic springs: c3 in slot 9, εc in slot 10)
  std::vector<std::array<double, 12>> material_table;
  bool hyperelastic = false;  ///< some tissue uses a hyperelastic law
  bool biphasic = false;      ///< some tissue uses biphasic springs
};

/// Materials by tissue name and anchors from the scene. Throws vb::Error when a tissue has no
/// material, a modulus or density is not positive, or an anchor holds nothing.
ElementArrays make_element_arrays(const Scene& scene, const Lattice& lattice);

/// Whether some tissue of the lattice is hyperelastic (ElementArrays::hyperelastic, without the
/// arrays); a tissue without a material counts as not.
bool has_hyperelastic_tissue(const Scene& scene, const Lattice& lattice);

}  // namespace vb
