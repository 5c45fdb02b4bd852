#pragma once
/// The unknowns of a fit: which elements share one Young's modulus (docs/FIT.md, "Unknowns").
#include <cstdint>
#include <string>
#include <vector>

#include "engine/fit/fit_spec.hpp"
#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"

namespace vb {

struct FitRegions {
  std::vector<std::int32_t> region_of_element;  ///< n; −1: not fitted (keeps its material's E)
  std::vector<std::string> names;               ///< per region: tissue name, "block_i_j_k", "e<N>"
  std::vector<std::size_t> element_count;       ///< per region
  std::size_t size() const { return names.size(); }
};

/// Regions over the fitted tissues (FitSpec::tissues; empty: every non-rigid tissue): one per
/// tissue, per cube of block_m (origin at the lattice's first voxel), or per element. Throws
/// vb::Error for a fitted tissue the model lacks or a rigid one.
FitRegions make_fit_regions(const FitSpec& fit, const Scene& scene, const Lattice& lattice);

}  // namespace vb
