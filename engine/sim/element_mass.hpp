#pragma once
/// Element masses: each element carries the mass of its share of its tissue's body
/// (docs/PHYSICS.md, "Mass"). Linear and biphasic springs model the union of the voxels, so an
/// element owns its voxel; hyperelastic tissue models the hull of the element centres, so an
/// element owns the octants of its voxel that are complete dual cells (w_e = cells/8).
#include <array>
#include <cstdint>
#include <vector>

#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/element_setup.hpp"

namespace vb {

/// The share given to a hyperelastic element with no complete dual cell around it (a one-voxel
/// strand or sheet, an isolated element): a corner's, ⅛ of a voxel, so that its inverse mass stays
/// finite; such elements are counted (TissueMass::floored) and the app warns.
inline constexpr double kLeastVolumeFraction = 0.125;

/// An element's mass over density·h³: 1 for spring (or rigid) tissue; for hyperelastic tissue its
/// dual-volume fraction (complete dual cells, of any tissue, around it over 8), at least
/// kLeastVolumeFraction.
double mass_volume_fraction(const std::array<std::int32_t, 26>& neighbours, bool hull_body);

/// The same for element e of arrays built by make_element_arrays (hyperelastic: law 1 or 2 in its
/// tissue's material_table row).
double mass_volume_fraction(const Lattice& lattice, const ElementArrays& elements, std::size_t e);

/// One tissue's mass three ways (kg) and what they come from.
struct TissueMass {
  double model_kg = 0;       ///< Σ element masses: what gravity loads
  double voxel_kg = 0;       ///< the union of its voxels: elements × density·h³
  double hull_kg = 0;        ///< its part of the hull of the element centres: Σ w_e·density·h³
  double density_kg_m3 = 0;
  std::size_t elements = 0;
  std::size_t floored = 0;   ///< hyperelastic elements with no complete dual cell (given the floor)
  bool hull_body = false;    ///< hyperelastic: its body is the hull of the element centres
};

/// Per tissue of the lattice (lattice.tissue_names order), from the scene's materials and the
/// element arrays' masses.
std::vector<TissueMass> tissue_masses(const Scene& scene, const Lattice& lattice, const ElementArrays& elements);

}  // namespace vb
