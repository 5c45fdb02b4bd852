#pragma once
/// The closed surface of the elastic body as a triangle mesh whose vertices are elements, so it
/// deforms with the model. docs/SURFACE.md has the definition, the pinch rule and the numbers.
///
/// The body is the union of the complete dual cells (cubes between 8 element centres). Every face
/// of a complete cell whose neighbour across it is not complete is a boundary face: a unit square
/// with 4 element corners, split into two triangles along the diagonal from its corner with the
/// lowest lattice coordinates to the opposite one. Around each surface element the incident
/// boundary faces are grouped into fans joined through shared edges; each fan is one mesh vertex.
/// Where two complete cells meet only along an edge or at a corner (a pinch) the cells count as
/// joined through faces only, so the two parts get separate vertices there (they touch
/// geometrically, but are topologically apart). The result is closed, 2-manifold (each edge in
/// exactly two triangles, one closed fan per vertex) and consistently oriented.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "engine/lattice/lattice.hpp"

namespace vb {

struct SurfaceMesh {
  /// mesh vertex → element index. An element on a pinch has one vertex per part it bounds.
  std::vector<std::uint32_t> element_of_vertex;
  /// vertex ids, counter-clockwise seen from outside the body in the world frame (so the normal
  /// (x1 − x0) × (x2 − x0) points out); two triangles per boundary face, consecutive
  std::vector<std::array<std::uint32_t, 3>> triangles;
  /// per vertex: outward unit normal at rest (world frame), the mean of the normals of the
  /// boundary faces of its fan; for shading and contact
  std::vector<Eigen::Vector3d> normal_of_vertex;

  std::size_t surface_element_count = 0;  ///< elements with 1–7 complete dual cells
  std::size_t complete_cell_count = 0;    ///< dual cells in the body: rest volume = this × h³
  std::size_t outside_body_count = 0;     ///< elements in no complete cell: no surface, no volume
  std::size_t split_element_count = 0;    ///< surface elements with more than one vertex (pinches)
  /// edges where two complete cells meet diagonally but whose faces had to pair around the empty
  /// cells instead (else the same two vertices would be joined by two edges; docs/SURFACE.md)
  std::size_t empty_paired_edge_count = 0;

  std::size_t vertex_count() const { return element_of_vertex.size(); }
};

/// Builds the surface of the lattice's body. Linear in the number of elements.
SurfaceMesh build_surface(const Lattice& lattice);

/// Element positions in the world frame (n_elements × 3, row-major, m): rest position plus
/// `displacement_m` (n_elements × 3, world frame, m; empty for the rest state).
std::vector<double> element_positions_m(const Lattice& lattice, std::span<const double> displacement_m = {});

}  // namespace vb
