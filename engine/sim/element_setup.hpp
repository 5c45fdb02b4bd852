#pragma once
/// Per-element physical arrays (double, SI) built from the scene and lattice; the simulator
/// uploads them in the chosen precision and the host reference uses them as they are.
#include <vector>

#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"

namespace vb {

struct ElementArrays {
  std::vector<double> youngs_modulus_pa;  ///< n
  std::vector<double> mass_kg;            ///< n, density × voxel volume
  std::vector<double> inverse_mass;       ///< n, 1/kg; 0 for held elements
  std::vector<double> displacement_m;     ///< n×3 initial (prescribed for held elements)
  std::size_t held_count = 0;
};

/// Materials by tissue name and anchors from the scene. Throws vb::Error when a tissue has no
/// material, a modulus or density is not positive, or an anchor holds nothing.
ElementArrays make_element_arrays(const Scene& scene, const Lattice& lattice);

}  // namespace vb
