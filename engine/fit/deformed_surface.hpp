#pragma once
/// The boundary of a region of the model after a simulated posture change, as a closed triangle
/// mesh: the observation a validation of surface-mesh fitting starts from (docs/FIT.md,
/// "Observation from a surface mesh").
#include <vector>

#include "engine/geometry/triangle_mesh.hpp"
#include "engine/lattice/lattice.hpp"

namespace vb {

/// Every voxel face between the region (tissue `tissue`'s elements; −1: every element, the body)
/// and the rest, two triangles per face, outward; its corners (lattice voxel corners, shared
/// between faces) moved by the posture change interpolated there (InterpolatedDisplacement: the
/// same field as deformed_label_map, so both observations show the same deformed boundary).
/// World frame (LPS, m). Throws vb::Error when the region has no element.
TriangleMesh deformed_boundary_mesh(const Lattice& lattice, const std::vector<double>& change_m, int tissue);

}  // namespace vb
