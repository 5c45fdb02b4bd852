#pragma once
/// Several copies of one lattice on one grid, so that one simulator relaxes independent models
/// together (batched forward solves of a fit, docs/FIT.md "Batched solves").
#include "engine/lattice/lattice.hpp"

namespace vb {

/// `copies` copies of `lattice` stacked along its z axis with one empty voxel layer between
/// them: every neighbour of an element (26, at most one voxel away) lies in its own copy or is
/// empty, so no spring, dashpot or deformation-gradient fit crosses copies. Element e of copy c
/// is element c·n + e (n = lattice.element_count()). `tissue_stride` > 0 gives copy c the tissue
/// ids t + c·tissue_stride (names "<name>@c"; each copy can then carry its own material rows);
/// 0 keeps the ids. Throws vb::Error when the ids exceed 255 or the grid 32-bit indexing.
Lattice tile_lattice(const Lattice& lattice, int copies, int tissue_stride = 0);

}  // namespace vb
