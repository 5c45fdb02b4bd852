#include "engine/sim/element_setup.hpp"

#include <cmath>

#include "engine/error.hpp"
#include "engine/loads/anchors.hpp"
#include "engine/material/biphasic_spring.hpp"
#include "engine/material/hyperelastic.hpp"
#include "engine/sim/element_mass.hpp"

namespace vb {

bool has_hyperelastic_tissue(const Scene& scene, const Lattice& lattice) {
  for (const std::string& tissue : lattice.tissue_names) {
    const auto it = scene.materials.find(tissue);
    if (it != scene.materials.end() && it->second.hyperelastic()) return true;
  }
  return false;
}

ElementArrays make_element_arrays(const Scene& scene, const Lattice& lattice) {
  const std::size_t n = lattice.element_count();
  require(n > 0, "the model has no elements", "model", "check the shapes, labels and downsample factor");
  const double volume = std::pow(lattice.spacing_m, 3);

  std::vector<double> E_of_tissue, stability_of_tissue, mass_of_tissue;
  std::vector<bool> rigid_tissue;  // held in place (bone)
  std::vector<bool> hull_tissue;   // hyperelastic: the body is the hull of the element centres
  ElementArrays a;
  for (const std::string& tissue : lattice.tissue_names) {
    auto it = scene.materials.find(tissue);
    require(it != scene.materials.end(), "tissue '" + tissue + "' has no material", "materials." + tissue);
    const MaterialSpec& m = it->second;
    const std::string where = "materials." + tissue + (m.line ? " (line " + std::to_string(m.line) + ")" : "");
    if (m.law == "linear" || m.law == "biphasic")  // hyperelastic laws check their own parameters (law_of)
      require(m.youngs_modulus_pa > 0 && std::isfinite(m.youngs_modulus_pa), "Young's modulus must be positive", where);
    require(m.density_kg_m3 > 0 && std::isfinite(m.density_kg_m3), "density must be positive", where);
    mass_of_tissue.push_back(m.density_kg_m3 * volume);
    rigid_tissue.push_back(m.rigid);
    hull_tissue.push_back(m.hyperelastic());
    std::array<double, 12> row{};  // law 0: linear springs
    if (m.law == "linear" || m.rigid) {
      E_of_tissue.push_back(m.youngs_modulus_pa);
      stability_of_tissue.push_back(m.youngs_modulus_pa);
    } else if (m.law == "biphasic") {
      // Springs of modulus E at small strain; the time step needs the stiffest tangent, reached
      // beyond ±εc (the dashpots keep E).
      const BiphasicSpring spring = biphasic_spring_of(m);
      E_of_tissue.push_back(m.youngs_modulus_pa);
      stability_of_tissue.push_back(m.youngs_modulus_pa * spring.stiffest_tangent());
      row[0] = 3;
      row[9] = spring.cubic;
      row[10] = spring.critical_strain;
      a.biphasic = true;
    } else {
      const HyperelasticLaw law = law_of(m);
      const double mu0 = law.shear_modulus_pa();
      E_of_tissue.push_back(2.5 * mu0);
      // The isochoric part's P-wave modulus 4/3·μ₀ over the lattice's C11/E = 1.2 and the
      // hourglass springs; the dual cells' volumetric stiffness is added to the Gershgorin rows
      // directly (engine/sim/time_step.cpp, dual_cell_row).
      stability_of_tissue.push_back(4.0 / 3.0 * mu0 / 1.2 + 2 * scene.solver.hourglass * 2.5 * mu0);
      row[0] = law.kind == HyperelasticLaw::Kind::Ogden ? 2 : 1;
      row[1] = law.terms;
      for (int p = 0; p < law.terms; ++p) {
        row[2 + p] = law.mu_pa[p];
        row[5 + p] = law.alpha[p];
      }
      row[8] = law.bulk_modulus_pa;
      a.hyperelastic = true;
    }
    a.material_table.push_back(row);
  }

  a.youngs_modulus_pa.resize(n);
  a.stability_modulus_pa.resize(n);
  a.mass_kg.resize(n);
  a.inverse_mass.resize(n);
  a.displacement_m.assign(3 * n, 0.0);
  const AnchorPlacement anchors = place_anchors(lattice, scene.anchors);
  for (std::size_t e = 0; e < n; ++e) {
    const int t = lattice.tissue_of_element[e];
    a.youngs_modulus_pa[e] = E_of_tissue[t];
    a.stability_modulus_pa[e] = stability_of_tissue[t];
    // Its share of its tissue's body: the voxel for springs, the octants of the voxel that are
    // complete dual cells (of any tissue) for hyperelastic tissue; never zero.
    a.mass_kg[e] = mass_of_tissue[t] * mass_volume_fraction(lattice.neighbours(e), hull_tissue[t]);
    a.inverse_mass[e] = anchors.held[e] || rigid_tissue[t] ? 0.0 : 1.0 / a.mass_kg[e];
    for (int c = 0; c < 3; ++c) a.displacement_m[3 * e + c] = anchors.displacement_m[e][c];
    a.held_count += a.inverse_mass[e] == 0;
  }
  require(a.held_count < n || n == 0, "every element is held by an anchor; nothing can move", "anchor");
  return a;
}

}  // namespace vb
