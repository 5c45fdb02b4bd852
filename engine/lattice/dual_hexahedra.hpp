#pragma once
/// The dual cells of a lattice (engine/lattice/dual_cells.hpp) as a hexahedral mesh over the
/// element centres: what viewers (.vtu) and finite-element codes (.feb) are given.
#include <array>
#include <cstdint>
#include <vector>

#include "engine/lattice/lattice.hpp"

namespace vb {

/// One hexahedron per 2×2×2 block of present element centres, its nodes the 8 elements (element
/// indices), ordered as a trilinear hex8 with positive volume in the world frame (VTK's and FEBio's
/// hexahedron order): the bottom face (i,j,k), (i+1,j,k), (i+1,j+1,k), (i,j+1,k) counter-clockwise
/// seen from the top, then the top face at k+1; where the lattice axes are left-handed in the world
/// the two faces swap. Cells come in the order of the element at their lowest corner.
std::vector<std::array<std::uint32_t, 8>> dual_hexahedra(const Lattice& lattice);

}  // namespace vb
