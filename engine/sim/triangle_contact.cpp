#include "engine/sim/triangle_contact.hpp"

#include <algorithm>
#include <cmath>

#include "engine/error.hpp"
#include "engine/sim/time_step.hpp"

namespace vb {

bool uses_triangle_contact(const Scene& scene) {
  return std::any_of(scene.indenters.begin(), scene.indenters.end(), [](const IndenterSpec& i) {
    return i.contact_surface == IndenterSpec::Surface::Triangles;
  });
}

void check_triangle_contact(const Scene& scene) {
  for (std::size_t k = 0; k < scene.indenters.size(); ++k) {
    const IndenterSpec& i = scene.indenters[k];
    if (i.contact_surface != IndenterSpec::Surface::Triangles) continue;
    const std::string where = "indenter " + std::to_string(k + 1) + (i.line ? " (line " + std::to_string(i.line) + ")" : "");
    require(i.kind == IndenterSpec::Kind::Sphere, "contact_surface = \"triangles\" is built for spheres only", where,
            "use kind = \"sphere\" (a point probe), or contact_surface = \"vertices\"");
    require(i.contact == IndenterSpec::Contact::Push, "triangle contact is unilateral (push) only", where,
            "use contact = \"push\", or contact_surface = \"vertices\"");
    require(i.contact_stiffness > 0 && std::isfinite(i.contact_stiffness), "contact_stiffness must be positive", where);
  }
}

TriangleContactPenalty triangle_contact_penalty(const Scene& scene, const Lattice& lattice, const ElementArrays& el,
                                                const SurfaceMesh& mesh) {
  TriangleContactPenalty p;
  p.stiffness_n_m.assign(scene.indenters.size(), 0.0);
  if (!uses_triangle_contact(scene)) return p;
  const std::vector<double> rows = element_row_stiffness_n_m(lattice, el);
  const double k_ref = rows.empty() ? 0.0 : *std::max_element(rows.begin(), rows.end());
  double k_sum = 0;
  for (std::size_t i = 0; i < scene.indenters.size(); ++i)
    if (scene.indenters[i].contact_surface == IndenterSpec::Surface::Triangles)
      k_sum += p.stiffness_n_m[i] = scene.indenters[i].contact_stiffness * k_ref;
  p.row_n_m.assign(lattice.element_count(), 0.0);
  for (const auto& t : mesh.triangles)
    for (const std::uint32_t v : t) p.row_n_m[mesh.element_of_vertex[v]] += std::sqrt(3.0) * k_sum;
  return p;
}

TriangleContactMesh triangle_contact_mesh(const SurfaceMesh& mesh, std::size_t n) {
  TriangleContactMesh m;
  const std::size_t T = mesh.triangles.size();
  m.triangles.resize(3 * T);
  m.start.assign(n + 1, 0);
  for (std::size_t t = 0; t < T; ++t)
    for (int c = 0; c < 3; ++c) {
      m.triangles[3 * t + c] = mesh.element_of_vertex[mesh.triangles[t][c]];
      ++m.start[m.triangles[3 * t + c] + 1];
    }
  for (std::size_t e = 0; e < n; ++e) m.start[e + 1] += m.start[e];
  m.corner.resize(3 * T);
  std::vector<std::uint32_t> fill(m.start.begin(), m.start.end() - 1);
  for (std::uint32_t k = 0; k < 3 * T; ++k) m.corner[fill[m.triangles[k]]++] = k;
  return m;
}

}  // namespace vb
