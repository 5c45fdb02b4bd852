#pragma once
/// Starting moduli and bounds of a fit (docs/FIT.md, "Initial guess and bounds").
#include <vector>

#include "engine/fit/fit_regions.hpp"
#include "engine/image/image_volume.hpp"

namespace vb {

/// HU of fat and of fibroglandular tissue that anchor the HU → E rule.
inline constexpr double kFatHu = -100.0, kGlandHu = 40.0;

/// The HU → E rule: log-linear between (kFatHu, E_fat) and (kGlandHu, E_gland), clamped to
/// [E_fat, E_gland]: E = E_fat·(E_gland/E_fat)^((HU − kFatHu)/(kGlandHu − kFatHu)).
double modulus_from_hu(double hu, double fat_pa, double gland_pa);

/// Mean HU of the CT voxels whose centres lie in each element's cube (n); an element no voxel
/// centre falls in takes the CT's value at its centre (nearest voxel).
std::vector<double> element_hu(const Lattice& lattice, const ImageVolume& ct);

/// Young's modulus a tissue's material gives (Pa): E of linear and biphasic springs; the
/// small-strain E = 9κμ₀/(3κ + μ₀) of a hyperelastic law (neo-Hookean, Mooney-Rivlin, Ogden).
/// Throws vb::Error for impossible hyperelastic constants (law_of).
double material_modulus_pa(const MaterialSpec& m);

/// Per region: the geometric mean over its elements of the material table's E.
std::vector<double> moduli_from_materials(const Scene& scene, const Lattice& lattice, const FitRegions& regions);

/// Per region: the geometric mean over its elements of modulus_from_hu(element HU), with E_fat
/// and E_gland the scene's (or default) adipose and fibroglandular moduli.
std::vector<double> moduli_from_hu(const Scene& scene, const Lattice& lattice, const FitRegions& regions,
                                   const std::vector<double>& hu);

/// Bounds: fit.min_E / max_E, else ¼ of the smallest and 10× the largest material-table E of the
/// fitted tissues.
std::pair<double, double> modulus_bounds(const FitSpec& fit, const Scene& scene, const Lattice& lattice,
                                         const FitRegions& regions);

}  // namespace vb
