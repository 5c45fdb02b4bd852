#include "engine/lattice/dual_hexahedra.hpp"

#include <Eigen/LU>

#include "engine/lattice/dual_cells.hpp"

namespace vb {

std::vector<std::array<std::uint32_t, 8>> dual_hexahedra(const Lattice& lattice) {
  const bool mirrored = lattice.rotation.determinant() < 0;
  const std::size_t sx = 1, sy = std::size_t(lattice.dims[0]), sz = sy * std::size_t(lattice.dims[1]);
  const std::size_t corner_offset[8] = {0, sx, sx + sy, sy, sz, sx + sz, sx + sy + sz, sy + sz};
  // the cell towards +x+y+z is octant 7; bit d of `present`: neighbour d exists
  const std::uint32_t upper_octant = octant_masks()[7];
  std::vector<std::array<std::uint32_t, 8>> hexes;
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    const auto neighbours = lattice.neighbours(e);
    std::uint32_t present = 0;
    for (int d = 0; d < 26; ++d)
      if (neighbours[d] >= 0) present |= 1u << d;
    if ((present & upper_octant) != upper_octant) continue;
    const std::size_t v = lattice.voxel_of_element[e];
    std::array<std::uint32_t, 8> hex{};
    for (int k = 0; k < 8; ++k)
      hex[k] = std::uint32_t(lattice.element_of_voxel[v + corner_offset[mirrored ? (k + 4) % 8 : k]]);
    hexes.push_back(hex);
  }
  return hexes;
}

}  // namespace vb
