#include "io/febio_file.hpp"

#include <pugixml.hpp>

#include <algorithm>

#include "engine/error.hpp"
#include "engine/lattice/dual_hexahedra.hpp"
#include "engine/material/hyperelastic.hpp"
#include "io/atomic_file.hpp"
#include "io/csv_table.hpp"

namespace vb {
namespace {

std::string number(double v) { return shortest_number_text(v); }

/// Lattice springs: an isotropic lattice with E and ν = 1/4 at small strain (docs/PHYSICS.md).
FebioMaterial spring_material(const MaterialSpec& m, std::string note) {
  return {"isotropic elastic",
          {{"density", m.density_kg_m3}, {"E", m.youngs_modulus_pa}, {"v", 0.25}},
          std::move(note)};
}

void add_value(pugi::xml_node parent, const char* name, const std::string& value) {
  parent.append_child(name).text().set(value.c_str());
}

}  // namespace

FebioMaterial febio_material(const MaterialSpec& m) {
  if (m.rigid)
    return spring_material(m, "rigid: its nodes are fixed; written as isotropic elastic with its E, which acts only "
                              "in cells shared with free tissue");
  if (m.law == "linear")
    return spring_material(m, "linear springs: the same small-strain response (E, nu = 1/4); FEBio's isotropic "
                              "elastic is St Venant-Kirchhoff at large strain");
  if (m.law == "biphasic")
    return spring_material(m, "biphasic springs: no FEBio equivalent; exported with the small-strain modulus E, "
                              "without the cubic stiffening");
  // W = sum_p mu_p/alpha_p (sum_i lbar_i^alpha_p - 3) + kappa/2 (J - 1)^2, FEBio's uncoupled laws
  // with U(J) = k/2 (J - 1)^2 (pressure_model "Abaqus")
  const HyperelasticLaw law = law_of(m);
  FebioMaterial out;
  out.parameters.emplace_back("density", m.density_kg_m3);
  if (law.kind == HyperelasticLaw::Kind::Ogden) {
    // FEBio's Ogden: sum_p c_p/m_p^2 (sum_i lbar_i^m_p - 3), so c_p = mu_p alpha_p
    out.type = "Ogden";
    for (int p = 0; p < law.terms; ++p) {
      out.parameters.emplace_back("c" + std::to_string(p + 1), law.mu_pa[p] * law.alpha[p]);
      out.parameters.emplace_back("m" + std::to_string(p + 1), law.alpha[p]);
    }
  } else {
    // neo-Hookean mu/2 (Ibar1 - 3) and Mooney-Rivlin C10 (Ibar1 - 3) + C01 (Ibar2 - 3): mu_1 = 2 C10,
    // mu_2 = -2 C01 with alpha = (2, -2)
    out.type = "Mooney-Rivlin";
    out.parameters.emplace_back("c1", law.mu_pa[0] / 2);
    out.parameters.emplace_back("c2", law.terms > 1 ? -law.mu_pa[1] / 2 : 0.0);
  }
  out.parameters.emplace_back("k", law.bulk_modulus_pa);
  return out;
}

FebioExportSummary write_febio(const std::string& path, const Scene& scene, const Lattice& lattice,
                               const std::vector<bool>& held) {
  const std::size_t n = lattice.element_count();
  require(held.size() == n, "held flags must have one entry per element", path);
  const auto hexes = dual_hexahedra(lattice);
  require(!hexes.empty(), "the model has no complete dual cell (2x2x2 block of elements) to export", path,
          "a hexahedral mesh needs a body at least two elements thick");

  // nodes: the elements that are corners of some cell, numbered from 1 in element order
  std::vector<std::uint32_t> node_of_element(n, 0);
  for (const auto& hex : hexes)
    for (const std::uint32_t e : hex) node_of_element[e] = 1;
  FebioExportSummary summary;
  for (std::size_t e = 0; e < n; ++e) {
    if (node_of_element[e]) node_of_element[e] = std::uint32_t(++summary.nodes);
    else ++summary.elements_left_out;
  }
  summary.hexahedra = hexes.size();

  // each cell's tissue: the most common among its corners, ties to the lower tissue index
  const std::size_t tissues = lattice.tissue_names.size();
  std::vector<std::vector<std::size_t>> cells_of_tissue(tissues);
  for (std::size_t c = 0; c < hexes.size(); ++c) {
    std::vector<int> votes(tissues, 0);
    for (const std::uint32_t e : hexes[c]) ++votes[lattice.tissue_of_element[e]];
    cells_of_tissue[std::size_t(std::max_element(votes.begin(), votes.end()) - votes.begin())].push_back(c);
  }

  pugi::xml_document doc;
  auto declaration = doc.append_child(pugi::node_declaration);
  declaration.append_attribute("version") = "1.0";
  declaration.append_attribute("encoding") = "ISO-8859-1";
  doc.append_child(pugi::node_comment)
      .set_value((" VoxBreast lattice of " + (scene.source_path.empty() ? std::string("a scene") : scene.source_path) +
                  ": nodes at element centres, one hex8 per dual cell; SI units (m, kg, s, Pa) ")
                     .c_str());
  auto spec = doc.append_child("febio_spec");
  spec.append_attribute("version") = "4.0";
  spec.append_child("Module").append_attribute("type") = "solid";

  auto control = spec.append_child("Control");
  add_value(control, "analysis", "STATIC");
  add_value(control, "time_steps", "10");
  add_value(control, "step_size", "0.1");
  control.append_child("solver").append_attribute("type") = "solid";

  auto materials = spec.append_child("Material");
  int material_id = 0;
  for (std::size_t t = 0; t < tissues; ++t) {
    if (cells_of_tissue[t].empty()) continue;
    const std::string& name = lattice.tissue_names[t];
    const auto it = scene.materials.find(name);
    require(it != scene.materials.end(), "tissue '" + name + "' has no material", path);
    const FebioMaterial m = febio_material(it->second);
    auto node = materials.append_child("material");
    node.append_attribute("id") = ++material_id;
    node.append_attribute("name") = name.c_str();
    node.append_attribute("type") = m.type.c_str();
    for (const auto& [key, value] : m.parameters) add_value(node, key.c_str(), number(value));
    if (m.type != "isotropic elastic") add_value(node, "pressure_model", "Abaqus");
    if (!m.note.empty()) summary.notes.push_back(name + ": " + m.note);
  }

  auto mesh = spec.append_child("Mesh");
  auto nodes = mesh.append_child("Nodes");
  nodes.append_attribute("name") = "lattice";
  for (std::size_t e = 0; e < n; ++e) {
    if (!node_of_element[e]) continue;
    const Eigen::Vector3d x = lattice.rest_position(e);
    auto node = nodes.append_child("node");
    node.append_attribute("id") = node_of_element[e];
    node.text().set((number(x.x()) + "," + number(x.y()) + "," + number(x.z())).c_str());
  }
  std::size_t element_id = 0;
  for (std::size_t t = 0; t < tissues; ++t) {
    if (cells_of_tissue[t].empty()) continue;
    auto block = mesh.append_child("Elements");
    block.append_attribute("type") = "hex8";
    block.append_attribute("name") = lattice.tissue_names[t].c_str();
    for (const std::size_t c : cells_of_tissue[t]) {
      std::string corners;
      for (const std::uint32_t e : hexes[c]) corners += (corners.empty() ? "" : ",") + std::to_string(node_of_element[e]);
      auto elem = block.append_child("elem");
      elem.append_attribute("id") = ++element_id;
      elem.text().set(corners.c_str());
    }
  }
  std::string fixed;
  for (std::size_t e = 0; e < n; ++e)
    if (held[e] && node_of_element[e]) {
      fixed += (fixed.empty() ? "" : ",") + std::to_string(node_of_element[e]);
      ++summary.fixed_nodes;
    }
  if (summary.fixed_nodes) {
    auto set = mesh.append_child("NodeSet");
    set.append_attribute("name") = "held";
    set.text().set(fixed.c_str());
  }

  auto domains = spec.append_child("MeshDomains");
  for (std::size_t t = 0; t < tissues; ++t) {
    if (cells_of_tissue[t].empty()) continue;
    auto domain = domains.append_child("SolidDomain");
    domain.append_attribute("name") = lattice.tissue_names[t].c_str();
    domain.append_attribute("mat") = lattice.tissue_names[t].c_str();
  }

  if (summary.fixed_nodes) {
    auto bc = spec.append_child("Boundary").append_child("bc");
    bc.append_attribute("name") = "held";
    bc.append_attribute("node_set") = "held";
    bc.append_attribute("type") = "zero displacement";
    for (const char* dof : {"x_dof", "y_dof", "z_dof"}) add_value(bc, dof, "1");
  }

  if (scene.gravity.active) {
    // FEBio's constant body load is a force per unit mass that enters with the opposite sign:
    // gravity g is written as -g
    auto load = spec.append_child("Loads").append_child("body_load");
    load.append_attribute("name") = "gravity";
    load.append_attribute("type") = "const";
    const char* axes[3] = {"x", "y", "z"};
    for (int c = 0; c < 3; ++c) {
      auto component = load.append_child(axes[c]);
      component.append_attribute("lc") = 1;
      component.text().set(number(-scene.gravity.acceleration_m_s2[c]).c_str());
    }
    auto controller = spec.append_child("LoadData").append_child("load_controller");
    controller.append_attribute("id") = 1;
    controller.append_attribute("name") = "ramp";
    controller.append_attribute("type") = "loadcurve";
    add_value(controller, "interpolate", "LINEAR");
    auto points = controller.append_child("points");
    add_value(points, "pt", "0,0");
    add_value(points, "pt", "1,1");
  }

  auto plot = spec.append_child("Output").append_child("plotfile");
  plot.append_attribute("type") = "febio";
  for (const char* var : {"displacement", "stress"}) plot.append_child("var").append_attribute("type") = var;

  AtomicOutput out(path);
  require(doc.save_file(out.temp_path().c_str(), "  ", pugi::format_default, pugi::encoding_latin1),
          "cannot write the FEBio file", path);
  out.commit();
  return summary;
}

}  // namespace vb
