#include "engine/fit/fit_regions.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "engine/error.hpp"

namespace vb {

FitRegions make_fit_regions(const FitSpec& fit, const Scene& scene, const Lattice& lattice) {
  const std::size_t n = lattice.element_count();
  std::vector<bool> fitted(lattice.tissue_names.size(), false);
  const auto rigid = [&](const std::string& t) {
    const auto it = scene.materials.find(t);
    return it != scene.materials.end() && it->second.rigid;
  };
  if (fit.tissues.empty()) {
    for (std::size_t t = 0; t < fitted.size(); ++t) fitted[t] = !rigid(lattice.tissue_names[t]);
  } else {
    for (const std::string& name : fit.tissues) {
      const auto it = std::find(lattice.tissue_names.begin(), lattice.tissue_names.end(), name);
      require(it != lattice.tissue_names.end(), "fitted tissue '" + name + "' is not in the model", "fit.tissues",
              "list tissues the model has (model.keep, the label table)");
      require(!rigid(name), "fitted tissue '" + name + "' is rigid", "fit.tissues", "leave it out");
      fitted[std::size_t(it - lattice.tissue_names.begin())] = true;
    }
  }

  FitRegions r;
  r.region_of_element.assign(n, -1);
  std::map<std::string, std::int32_t> index;  // region name → index, in order of first element
  const int block = fit.regions == FitSpec::Regions::Blocks
                        ? std::max(1, int(std::lround(fit.block_m / lattice.spacing_m)))
                        : 1;
  for (std::size_t e = 0; e < n; ++e) {
    const std::size_t t = lattice.tissue_of_element[e];
    if (!fitted[t]) continue;
    std::string name;
    switch (fit.regions) {
      case FitSpec::Regions::Labels: name = lattice.tissue_names[t]; break;
      case FitSpec::Regions::Elements: name = "e" + std::to_string(e); break;
      case FitSpec::Regions::Blocks: {
        const auto ijk = lattice.voxel_ijk(e);
        name = "block_" + std::to_string(ijk[0] / block) + "_" + std::to_string(ijk[1] / block) + "_" +
               std::to_string(ijk[2] / block);
        break;
      }
    }
    auto [it, added] = index.emplace(name, std::int32_t(r.names.size()));
    if (added) {
      r.names.push_back(name);
      r.element_count.push_back(0);
    }
    r.region_of_element[e] = it->second;
    ++r.element_count[std::size_t(it->second)];
  }
  require(!r.names.empty(), "no element is fitted", "fit.tissues", "fit at least one soft tissue");
  return r;
}

}  // namespace vb
