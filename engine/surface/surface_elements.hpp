#pragma once
/// Surface elements of the elastic body, and the paper's summed-direction normal estimate.
///
/// The body of the lattice is the union of its complete dual cells (docs/PHYSICS.md, "Element
/// volume"; engine/lattice/dual_cells.hpp). Its surface runs through element centres, so the
/// surface elements are those with some but not all of their 8 dual cells complete.
/// docs/SURFACE.md gives the definitions and the pinch rule.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "engine/lattice/lattice.hpp"

namespace vb {

/// For each element (n_elements), bit o set when the dual cell in octant o is complete; octant o
/// lies on the + side of axis a where bit a of o is set (octant_masks() order). 0: the element
/// is in no complete cell (a strand or sheet one voxel thick, not part of the body); 0xFF:
/// interior; anything else: a surface element.
std::vector<std::uint8_t> complete_octants_of_elements(const Lattice& lattice);

struct SurfaceElements {
  /// surface elements, ascending: those with 1 to 7 complete dual cells around them
  std::vector<std::uint32_t> element;
  /// per surface element: the sum of the unit offsets d/|d| of its missing neighbours,
  /// normalised (world frame, unitless); it points out of the body. Zero where the missing
  /// directions cancel (rare: e.g. an element between two opposite notches).
  std::vector<Eigen::Vector3d> outward_normal;
};

/// Surface elements and their summed-direction normals. An element has 1–7 complete dual cells
/// exactly when it is in the body and lacks at least one of its 26 connections (each missing
/// neighbour empties every dual cell it is a corner of, and every incomplete cell lacks one of the
/// element's neighbours): the paper's test with its sensitivity threshold at zero, restricted to
/// elements of the body.
SurfaceElements find_surface_elements(const Lattice& lattice);

/// Number of surface elements (as find_surface_elements(lattice).element.size()).
std::size_t count_surface_elements(const Lattice& lattice);

/// Number of complete dual cells (the body's rest volume is this × h³).
std::size_t count_complete_dual_cells(const Lattice& lattice);

}  // namespace vb
