#include "engine/sim/element_mass.hpp"

#include <algorithm>
#include <cmath>

#include "engine/lattice/dual_cells.hpp"

namespace vb {

double mass_volume_fraction(const std::array<std::int32_t, 26>& neighbours, bool hull_body) {
  return hull_body ? std::max(dual_volume_fraction(neighbours), kLeastVolumeFraction) : 1.0;
}

double mass_volume_fraction(const Lattice& lattice, const ElementArrays& elements, std::size_t e) {
  const double law = elements.material_table.empty() ? 0 : elements.material_table[lattice.tissue_of_element[e]][0];
  return mass_volume_fraction(lattice.neighbours(e), law == 1 || law == 2);
}

std::vector<TissueMass> tissue_masses(const Scene& scene, const Lattice& lattice, const ElementArrays& elements) {
  const double volume = std::pow(lattice.spacing_m, 3);
  std::vector<TissueMass> out(lattice.tissue_names.size());
  for (std::size_t t = 0; t < out.size(); ++t) {
    const MaterialSpec& m = scene.materials.at(lattice.tissue_names[t]);
    out[t].density_kg_m3 = m.density_kg_m3;
    out[t].hull_body = m.hyperelastic();  // not rigid tissue: held whole, it keeps its voxels
  }
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    TissueMass& tm = out[lattice.tissue_of_element[e]];
    const double dual = dual_volume_fraction(lattice.neighbours(e));
    tm.elements += 1;
    tm.model_kg += elements.mass_kg[e];
    tm.voxel_kg += tm.density_kg_m3 * volume;
    tm.hull_kg += tm.density_kg_m3 * volume * dual;
    tm.floored += tm.hull_body && dual == 0;
  }
  return out;
}

}  // namespace vb
