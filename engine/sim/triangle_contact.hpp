#pragma once
/// Host side of indenter contact with the surface triangles (`[[indenter]] contact_surface =
/// "triangles"`, kernels/triangle_contact.cl, docs/PROBING.md): the penalty stiffness, its share
/// of the stable time step, and the mesh arrays the kernels read.
#include <cstdint>
#include <vector>

#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/element_setup.hpp"
#include "engine/surface/surface_mesh.hpp"

namespace vb {

/// Whether some indenter of the scene touches the surface triangles.
bool uses_triangle_contact(const Scene& scene);

/// Throws vb::Error when an indenter asks for triangle contact in a way that is not built: a shape
/// other than a sphere, slide or stick contact. (Friction is built: kernels/triangle_contact.cl.)
void check_triangle_contact(const Scene& scene);

struct TriangleContactPenalty {
  /// per indenter: k_p (N/m), contact_stiffness × the largest Gershgorin row stiffness of a free
  /// element (the stiffest element's own stiffness scale); 0 for vertex contact
  std::vector<double> stiffness_n_m;
  /// per element: Gershgorin bound of the penalty's stiffness on its rows (N/m), √3·Σ k_p times
  /// the number of triangle corners it is (each touching triangle adds at most w·k_p·|n_a|·‖n‖₁ ≤
  /// √3·k_p to a row, w ≤ 1); added to the elastic bound in the stable step and in relaxation's
  /// mass scaling. Empty when no indenter uses triangle contact.
  std::vector<double> row_n_m;
};

/// The penalty of the scene's triangle-contact indenters on the surface `mesh`.
TriangleContactPenalty triangle_contact_penalty(const Scene& scene, const Lattice& lattice,
                                                const ElementArrays& elements, const SurfaceMesh& mesh);

/// The surface mesh as the kernels read it.
struct TriangleContactMesh {
  std::vector<std::uint32_t> triangles;  ///< 3 element ids per triangle, the mesh's order
  std::vector<std::uint32_t> start;   ///< per element (n + 1): its range in `corner`
  std::vector<std::uint32_t> corner;  ///< 3·triangle + corner, grouped by element
};

TriangleContactMesh triangle_contact_mesh(const SurfaceMesh& mesh, std::size_t element_count);

}  // namespace vb
