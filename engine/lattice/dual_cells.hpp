#pragma once
/// Dual cells: the cube between 8 neighbouring element centres. The union of the dual cells is
/// the elastic body of hyperelastic tissue (its surface runs through the outer element centres,
/// where plates and anchors touch the lattice); docs/PHYSICS.md, "Element volume".
#include <array>
#include <cstdint>

#include <Eigen/Core>

namespace vb {

/// For each of the 8 octants around an element, the bit mask (bit d = neighbour_offsets()[d]) of
/// the 7 neighbours that, with the element, form the dual cell in that octant.
const std::array<std::uint32_t, 8>& octant_masks();

/// Fraction of an element's dual volume h³ that lies in the body: (complete dual cells around
/// it)/8. 1 inside, ½ on a flat face, ¼ on an edge, ⅛ at a corner, 0 in a one-voxel strand.
double dual_volume_fraction(const std::array<std::int32_t, 26>& neighbours);

/// Volume (m³) of the trilinear hexahedron with corners p[i + 2j + 4k] ((i, j, k) ∈ {0, 1}³,
/// right-handed: positive for an undeformed dual cell) and its gradient with respect to each corner
/// (m²). Exact: the volume is expanded into the triple products of the map's coefficient vectors,
/// each weighted by the integral of its monomial over the unit cube.
struct TrilinearVolume {
  double volume_m3 = 0;
  std::array<Eigen::Vector3d, 8> gradient_m2;
};
TrilinearVolume trilinear_volume(const std::array<Eigen::Vector3d, 8>& p);

}  // namespace vb
