#pragma once
/// A per-element quantity handed to the mesh writers to colour a mesh by.
#include <span>
#include <string>

namespace vb {

struct ElementField {
  /// array name in the file, ending in its unit like every VoxBreast output ("von_mises_stress_pa",
  /// "equivalent_strain" for a dimensionless one)
  std::string name;
  std::span<const double> values;  ///< n_elements × components, row-major
  int components = 1;
};

}  // namespace vb
