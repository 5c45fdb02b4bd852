#pragma once
/// A scene's lattice as an FEBio model (.feb, FEBio input spec 4.0): the dual cells of the element
/// centres as hex8 elements, the tissues' laws as FEBio materials, held elements as fixed nodes
/// and gravity as a constant body load, in SI units (m, kg, s, Pa). docs/EXPORT.md lists the
/// mapping of every law.
#include <string>
#include <utility>
#include <vector>

#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"

namespace vb {

/// One FEBio material: its type and parameters in the order written; `note` says how it differs
/// from VoxBreast's law (empty where the strain energy is the same).
struct FebioMaterial {
  std::string type;
  std::vector<std::pair<std::string, double>> parameters;
  std::string note;
};

/// The FEBio material of a VoxBreast material (density included). Throws vb::Error for impossible
/// hyperelastic parameters (as the simulator does).
FebioMaterial febio_material(const MaterialSpec& material);

/// What was written.
struct FebioExportSummary {
  std::size_t nodes = 0;             ///< element centres that are corners of some hexahedron
  std::size_t hexahedra = 0;
  std::size_t fixed_nodes = 0;
  std::size_t elements_left_out = 0;  ///< elements in no complete dual cell (one-voxel strands)
  std::vector<std::string> notes;     ///< per tissue, where FEBio's law differs from VoxBreast's
};

/// Writes the .feb file atomically. `held` (n_elements): elements that do not move. Each
/// hexahedron takes the tissue most of its 8 corners have (ties: the tissue listed first in the
/// lattice). Throws vb::Error when the lattice has no complete dual cell or a tissue has no material.
FebioExportSummary write_febio(const std::string& path, const Scene& scene, const Lattice& lattice,
                               const std::vector<bool>& held);

}  // namespace vb
