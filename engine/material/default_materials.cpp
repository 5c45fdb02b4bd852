#include "engine/material/default_materials.hpp"

#include <array>

namespace vb {
namespace {

struct Default {
  const char* tissue;
  double youngs_modulus_pa;
  double density_kg_m3;
  bool rigid;
};

// Small-strain values; docs/MATERIALS.md gives each source and the reported spread.
constexpr std::array<Default, 9> kDefaults = {{
    {"adipose", 3250, 950, false},          // Samani et al. 2007, normal fat mean
    {"fibroglandular", 6000, 1040, false},  // ≈ 2× adipose, within the reported contrast range
    {"skin", 80000, 1090, false},           // modelling assumption (stiff thin layer), see docs
    {"muscle", 20000, 1050, false},         // modelling assumption for pectoral muscle, see docs
    {"bone", 1e9, 1920, true},              // held rigid; ρ of cortical bone (ICRU 44)
    {"tumour", 20000, 1050, false},         // = idc, intermediate grade (Samani et al. 2007)
    {"idc", 20000, 1050, false},            // Samani et al. 2007, ≈ 20 kPa intermediate grade
    {"dcis", 16400, 1050, false},           // Samani et al. 2007, ≈ 16.4 kPa
    {"fibroadenoma", 6400, 1050, false},    // Samani et al. 2007, ≈ 6.4 kPa
}};

}  // namespace

std::optional<MaterialSpec> default_material(const std::string& tissue) {
  for (const Default& d : kDefaults) {
    if (tissue != d.tissue) continue;
    MaterialSpec m;
    m.name = tissue;
    m.youngs_modulus_pa = d.youngs_modulus_pa;
    m.density_kg_m3 = d.density_kg_m3;
    m.rigid = d.rigid;
    return m;
  }
  return std::nullopt;
}

std::vector<std::string> default_material_names() {
  std::vector<std::string> names;
  for (const Default& d : kDefaults) names.emplace_back(d.tissue);
  return names;
}

}  // namespace vb
