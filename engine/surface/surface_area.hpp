#pragma once
/// Area of the surface mesh that each element stands for: a third of the area of every triangle
/// at its vertices (summed over an element's vertices at a pinch). On a flat face of the lattice
/// this is h² per element; the shares add up to the whole surface area. Contact pressure is the
/// contact force on an element over its share (docs/PHYSICS.md, "Torus device").
#include <span>
#include <vector>

#include "engine/surface/surface_mesh.hpp"

namespace vb {

/// Per element (n_elements), its share of the surface area (m²) at `positions_m` (n_elements × 3,
/// world frame, m); 0 for elements not on the mesh.
std::vector<double> element_surface_area_m2(const SurfaceMesh& mesh, std::span<const double> positions_m);

}  // namespace vb
