#include "engine/fit/initial_guess.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "engine/error.hpp"
#include "engine/material/hyperelastic.hpp"
#include "engine/material/default_materials.hpp"

namespace vb {
namespace {

double tissue_modulus(const Scene& scene, const std::string& tissue) {
  if (const auto it = scene.materials.find(tissue); it != scene.materials.end()) return material_modulus_pa(it->second);
  if (const auto d = default_material(tissue)) return material_modulus_pa(*d);
  throw Error("tissue '" + tissue + "' has no material", "fit", "define [materials." + tissue + "]");
}

std::vector<double> geometric_means(const FitRegions& regions, const std::vector<double>& element_value) {
  std::vector<double> sum(regions.size(), 0.0);
  for (std::size_t e = 0; e < element_value.size(); ++e)
    if (regions.region_of_element[e] >= 0) sum[std::size_t(regions.region_of_element[e])] += std::log(element_value[e]);
  for (std::size_t r = 0; r < sum.size(); ++r) sum[r] = std::exp(sum[r] / double(regions.element_count[r]));
  return sum;
}

}  // namespace

double modulus_from_hu(double hu, double fat_pa, double gland_pa) {
  const double t = std::clamp((hu - kFatHu) / (kGlandHu - kFatHu), 0.0, 1.0);
  return fat_pa * std::pow(gland_pa / fat_pa, t);
}

std::vector<double> element_hu(const Lattice& lattice, const ImageVolume& ct) {
  const std::size_t n = lattice.element_count();
  std::vector<double> sum(n, 0.0), count(n, 0.0);
  const Eigen::Matrix4d to_lattice = lattice.affine().inverse();
  for (int k = 0; k < ct.dims[2]; ++k)
    for (int j = 0; j < ct.dims[1]; ++j)
      for (int i = 0; i < ct.dims[0]; ++i) {
        const Eigen::Vector3d p = ct.world_of_index(Eigen::Vector3d(i, j, k));
        const Eigen::Vector3d q = (to_lattice * p.homogeneous()).head<3>();
        const int a = int(std::lround(q.x())), b = int(std::lround(q.y())), c = int(std::lround(q.z()));
        if (a < 0 || b < 0 || c < 0 || a >= lattice.dims[0] || b >= lattice.dims[1] || c >= lattice.dims[2]) continue;
        const std::int32_t e = lattice.element_of_voxel[std::size_t(a) + std::size_t(lattice.dims[0]) *
                                                                         (std::size_t(b) + std::size_t(lattice.dims[1]) * c)];
        if (e < 0) continue;
        sum[std::size_t(e)] += ct.values[ct.linear_index(i, j, k)];
        count[std::size_t(e)] += 1;
      }
  const Eigen::Matrix4d to_ct = ct.affine_lps_m.inverse();
  for (std::size_t e = 0; e < n; ++e) {
    if (count[e] > 0) {
      sum[e] /= count[e];
      continue;
    }
    const Eigen::Vector3d q = (to_ct * lattice.rest_position(e).homogeneous()).head<3>();
    const int i = std::clamp(int(std::lround(q.x())), 0, ct.dims[0] - 1);
    const int j = std::clamp(int(std::lround(q.y())), 0, ct.dims[1] - 1);
    const int k = std::clamp(int(std::lround(q.z())), 0, ct.dims[2] - 1);
    sum[e] = ct.values[ct.linear_index(i, j, k)];
  }
  return sum;
}

double material_modulus_pa(const MaterialSpec& m) {
  if (!m.hyperelastic()) return m.youngs_modulus_pa;
  // Hyperelastic: the small-strain E = 9κμ₀/(3κ + μ₀) of the law (for neo-Hookean with κ from ν
  // this is E itself).
  if (m.law == "neo-hookean" && m.bulk_modulus_pa <= 0) return m.youngs_modulus_pa;
  return law_of(m).youngs_modulus_pa();
}

std::vector<double> moduli_from_materials(const Scene& scene, const Lattice& lattice, const FitRegions& regions) {
  std::vector<double> table(lattice.tissue_names.size());
  for (std::size_t t = 0; t < table.size(); ++t) {
    bool used = false;
    for (std::size_t e = 0; e < lattice.element_count() && !used; ++e)
      used = regions.region_of_element[e] >= 0 && lattice.tissue_of_element[e] == t;
    table[t] = used ? tissue_modulus(scene, lattice.tissue_names[t]) : 1.0;
  }
  std::vector<double> element(lattice.element_count());
  for (std::size_t e = 0; e < element.size(); ++e) element[e] = table[lattice.tissue_of_element[e]];
  return geometric_means(regions, element);
}

std::vector<double> moduli_from_hu(const Scene& scene, const Lattice&, const FitRegions& regions,
                                   const std::vector<double>& hu) {
  const double fat = tissue_modulus(scene, "adipose"), gland = tissue_modulus(scene, "fibroglandular");
  std::vector<double> element(hu.size());
  for (std::size_t e = 0; e < hu.size(); ++e) element[e] = modulus_from_hu(hu[e], fat, gland);
  return geometric_means(regions, element);
}

std::pair<double, double> modulus_bounds(const FitSpec& fit, const Scene& scene, const Lattice& lattice,
                                         const FitRegions& regions) {
  double lo = INFINITY, hi = 0;
  std::vector<bool> seen(lattice.tissue_names.size(), false);
  for (std::size_t e = 0; e < lattice.element_count(); ++e)
    if (regions.region_of_element[e] >= 0) seen[lattice.tissue_of_element[e]] = true;
  for (std::size_t t = 0; t < seen.size(); ++t) {
    if (!seen[t]) continue;
    const double E = tissue_modulus(scene, lattice.tissue_names[t]);
    lo = std::min(lo, E);
    hi = std::max(hi, E);
  }
  return {fit.min_modulus_pa > 0 ? fit.min_modulus_pa : 0.25 * lo, fit.max_modulus_pa > 0 ? fit.max_modulus_pa : 10 * hi};
}

}  // namespace vb
