#include "engine/study/positioning_metrics.hpp"

#include <algorithm>
#include <cmath>

#include "engine/error.hpp"
#include "engine/surface/surface_mesh.hpp"

namespace vb {
namespace {

Vec3 position(const std::vector<double>& x, std::size_t e) { return Vec3(x[3 * e], x[3 * e + 1], x[3 * e + 2]); }

/// The tumour tissue's index in the lattice, or -1 when the scene names none and has no "tumour".
int tumour_tissue_index(const Scene& scene, const Lattice& lattice) {
  const std::string& asked = scene.positioning.tumour_tissue;
  const std::string name = asked.empty() ? "tumour" : asked;
  const auto it = std::find(lattice.tissue_names.begin(), lattice.tissue_names.end(), name);
  if (it != lattice.tissue_names.end()) return int(it - lattice.tissue_names.begin());
  require(asked.empty(), "positioning.tumour_tissue '" + asked + "' is not a tissue of the model",
          "positioning.tumour_tissue (line " + std::to_string(scene.positioning.line) + ")",
          "name a tissue the model has (check model.keep and the label table)");
  return -1;
}

/// Value at fraction q of the sorted values (nearest rank); 0 for none.
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const std::size_t rank = std::max<std::size_t>(1, std::size_t(std::ceil(q * double(v.size()))));
  const std::size_t k = std::min(v.size(), rank) - 1;
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  return v[k];
}

}  // namespace

const AnchorSpec* chest_wall_anchor(const Scene& scene) {
  const std::string& name = scene.positioning.chest_wall;
  const AnchorSpec* only_sphere = nullptr;
  int spheres = 0;
  for (const AnchorSpec& a : scene.anchors) {
    if (!name.empty() && a.name == name) return &a;
    if (a.kind == AnchorSpec::Kind::Sphere) only_sphere = &a, ++spheres;
  }
  return name.empty() && spheres == 1 ? only_sphere : nullptr;
}

void check_positioning(const Scene& scene, const Lattice& lattice) { (void)tumour_tissue_index(scene, lattice); }

double distance_from_anchor_m(const AnchorSpec& a, const Vec3& x) {
  switch (a.kind) {
    case AnchorSpec::Kind::Sphere:
      return (x - a.center_m).norm() - a.radius_m;
    case AnchorSpec::Kind::HalfSpace:
      return -(x - a.point_m).dot(a.normal);
    case AnchorSpec::Kind::Box:
      break;
  }
  throw Error("a box anchor has no chest-wall surface", "anchor." + a.name, "use a sphere or halfspace anchor");
}

PositioningMetrics compute_positioning_metrics(const Scene& scene, const Lattice& lattice, const ElementArrays& el,
                                               const RunSummary& summary, const FinalState& state) {
  const std::size_t n = lattice.element_count();
  require(state.position_m.size() == 3 * n, "final state does not match the model", "positioning");
  const std::vector<double> rest = element_positions_m(lattice);
  PositioningMetrics m;
  m.volume_change = summary.volume_change;
  m.surface_volume_change = summary.surface_volume_change;

  if (const int tissue = tumour_tissue_index(scene, lattice); tissue >= 0) {
    TumourMetrics t;
    t.tissue = lattice.tissue_names[std::size_t(tissue)];
    double mass = 0;
    for (std::size_t e = 0; e < n; ++e) {
      if (lattice.tissue_of_element[e] != tissue) continue;
      ++t.elements;
      mass += el.mass_kg[e];
      t.rest_centroid_m += el.mass_kg[e] * position(rest, e);
      t.final_centroid_m += el.mass_kg[e] * position(state.position_m, e);
    }
    t.rest_centroid_m /= mass;
    t.final_centroid_m /= mass;
    t.target_m = scene.positioning.target_m;
    if (t.target_m) {
      t.rest_target_distance_m = (t.rest_centroid_m - *t.target_m).norm();
      t.final_target_distance_m = (t.final_centroid_m - *t.target_m).norm();
    }
    m.tumour = t;
  }

  if (const AnchorSpec* wall = chest_wall_anchor(scene)) {
    ChestWallMetrics c;
    c.anchor = wall->name;
    if (m.tumour) {
      c.tumour_rest_m = distance_from_anchor_m(*wall, m.tumour->rest_centroid_m);
      c.tumour_final_m = distance_from_anchor_m(*wall, m.tumour->final_centroid_m);
    }
    double mass = 0;
    c.max_rest_m = c.max_final_m = -INFINITY;
    for (std::size_t e = 0; e < n; ++e) {
      if (el.inverse_mass[e] == 0) continue;  // held: part of the chest wall, or rigid
      const double d0 = distance_from_anchor_m(*wall, position(rest, e));
      const double d1 = distance_from_anchor_m(*wall, position(state.position_m, e));
      mass += el.mass_kg[e];
      c.mean_rest_m += el.mass_kg[e] * d0;
      c.mean_final_m += el.mass_kg[e] * d1;
      c.max_rest_m = std::max(c.max_rest_m, d0);
      c.max_final_m = std::max(c.max_final_m, d1);
    }
    if (mass > 0) {
      c.mean_rest_m /= mass;
      c.mean_final_m /= mass;
      m.chest_wall = c;
    }
  }

  std::vector<double> strain, stress;
  for (std::size_t e = 0; e < n; ++e) {
    const auto it = scene.materials.find(lattice.tissue_names[lattice.tissue_of_element[e]]);
    if (it != scene.materials.end() && it->second.rigid) continue;
    if (e < state.equivalent_strain.size()) strain.push_back(state.equivalent_strain[e]);
    if (e < state.von_mises_stress_pa.size()) stress.push_back(state.von_mises_stress_pa[e]);
  }
  m.comfort.peak_equivalent_strain = strain.empty() ? 0 : *std::max_element(strain.begin(), strain.end());
  m.comfort.peak_von_mises_pa = stress.empty() ? 0 : *std::max_element(stress.begin(), stress.end());
  m.comfort.p95_equivalent_strain = quantile(strain, 0.95);
  m.comfort.p95_von_mises_pa = quantile(stress, 0.95);
  return m;
}

}  // namespace vb
