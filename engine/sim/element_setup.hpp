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
  /// n, density × the element's share of its tissue's body: the voxel volume h³ for linear and
  /// biphasic springs (their body is the union of the voxels), w_e·h³ for hyperelastic tissue (the
  /// hull of the element centres; w_e = volume_fraction, docs/PHYSICS.md "Mass")
  std::vector<double> mass_kg;
  /// n, mass_kg over density × h³: w_e (complete dual cells around e, over 8; at least
  /// kLeastVolumeFraction) for hyperelastic tissue, 1 otherwise
  std::vector<double> volume_fraction;
  std::vector<double> inverse_mass;       ///< n, 1/kg; 0 for held elements
  std::vector<double> displacement_m;     ///< n×3 initial (prescribed for held elements)
  std::size_t held_count = 0;
  /// per tissue, the kernels' material table row (kernels/hyperelastic.cl: law, N, μ_p, α_p, κ;
  /// law 3, biphasic springs: c3 in slot 9, εc in slot 10)
  std::vector<std::array<double, 12>> material_table;
  /// per tissue, its mass three ways (kg): the model's (Σ mass_kg), the union of its voxels'
  /// (elements × density·h³) and the hull of the element centres' (Σ w_e·density·h³)
  struct TissueMass {
    double model_kg = 0, voxel_kg = 0, hull_kg = 0;
    double density_kg_m3 = 0;
    std::size_t elements = 0;
    std::size_t floored = 0;  ///< hyperelastic elements with no complete dual cell, given the floor
    bool hull_body = false;   ///< hyperelastic: the body is the hull of the element centres
  };
  std::vector<TissueMass> tissue_mass;
  bool hyperelastic = false;  ///< some tissue uses a hyperelastic law
  bool biphasic = false;      ///< some tissue uses biphasic springs
};

/// The mass given to a hyperelastic element with no complete dual cell around it (a one-voxel
/// strand or sheet, an isolated element): a corner's share, ⅛ of a voxel, so that its inverse mass
/// stays finite; the app warns when a tissue has such elements.
inline constexpr double kLeastVolumeFraction = 0.125;

/// Materials by tissue name and anchors from the scene. Throws vb::Error when a tissue has no
/// material, a modulus or density is not positive, or an anchor holds nothing.
ElementArrays make_element_arrays(const Scene& scene, const Lattice& lattice);

/// Whether some tissue of the lattice is hyperelastic (ElementArrays::hyperelastic, without the
/// arrays); a tissue without a material counts as not.
bool has_hyperelastic_tissue(const Scene& scene, const Lattice& lattice);

}  // namespace vb
