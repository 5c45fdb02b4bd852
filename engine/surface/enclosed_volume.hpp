#pragma once
/// The volume enclosed by a deformed surface mesh and its gradient with respect to the element
/// positions (for a volume-preservation constraint).
#include <span>
#include <vector>

#include "engine/surface/surface_mesh.hpp"

namespace vb {

/// Signed enclosed volume (m³): Σ over triangles of (1/6)·x0·(x1 × x2), positions taken relative
/// to the first vertex (the sum does not depend on the origin for a closed mesh; this keeps
/// rounding small far from the world origin). `positions_m`: n_elements × 3, row-major, world
/// frame (m), e.g. element_positions_m(). Positive for an outward-oriented mesh; at rest it is
/// mesh.complete_cell_count × h³. In the lattice frame (rotationᵀ·(x − origin)) it is multiplied
/// by det(rotation) = ±1.
double enclosed_volume_m3(const SurfaceMesh& mesh, std::span<const double> positions_m);

/// ∂V/∂x for every element (n_elements × 3, row-major, m²; zero off the surface), summed over the
/// vertices that share an element at a pinch. Same frame and sign convention as the positions.
std::vector<double> volume_gradient_m2(const SurfaceMesh& mesh, std::span<const double> positions_m);

}  // namespace vb
