#pragma once
// Helpers for simulator tests: scenes built in code and one OpenCL context per test binary.
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "engine/lattice/voxelise.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/element_setup.hpp"
#include "engine/sim/opencl_runtime.hpp"
#include "engine/sim/simulator.hpp"

namespace vb::test {

/// `o` with the stepping kernels made the real4 kernels with one work-item per element (or listed
/// element), in the elements' order: not the CPU lanes kernels, the one-launch step (GPUs) or the
/// split force pass (GPUs, hyperelastic), each of which keeps its own range, order and list.
inline PlanOverrides one_item_per_element(PlanOverrides o = {}) {
  o.lanes = false;
  o.persistent = false;
  o.force_split = 1;
  return o;
}

/// The default device (PoCL in CI), created once.
inline const ClContext& cl_context() {
  static const std::unique_ptr<ClContext> cl = std::make_unique<ClContext>(select_device(""));
  return *cl;
}

inline MaterialSpec material(const std::string& name, double E_pa, double density = 1000) {
  MaterialSpec m;
  m.name = name;
  m.youngs_modulus_pa = E_pa;
  m.density_kg_m3 = density;
  return m;
}

/// Box of nx×ny×nz voxels of spacing h with its minimum corner at the origin, tissue "soft".
inline Scene box_scene(int nx, int ny, int nz, double h, double E_pa = 3000) {
  Scene s;
  ShapeSpec box;
  box.kind = ShapeSpec::Kind::Box;
  box.min_m = Vec3::Zero();
  box.max_m = h * Vec3(nx, ny, nz);
  box.label = "soft";
  s.model.spacing_m = h;
  s.model.shapes.push_back(box);
  s.materials["soft"] = material("soft", E_pa);
  s.solver.dashpot_ratio = 0;
  return s;
}

inline AnchorSpec halfspace_anchor(const std::string& name, const Vec3& point, const Vec3& normal) {
  AnchorSpec a;
  a.name = name;
  a.kind = AnchorSpec::Kind::HalfSpace;
  a.point_m = point;
  a.normal = normal;
  return a;
}

/// A 9×9×10 block of soft tissue (E = 3 kPa, h = 4 mm) with a stiff inclusion (another E), a heavy
/// layer (the same E, another density: another mass) and a held base layer, under oblique gravity,
/// in double, with dashpots except for relaxation (its own damping): every kind of neighbour a
/// stepping kernel can meet (UniformPath, StepList).
inline Scene mixed_block(Integrator integrator, bool volume) {
  Scene s = box_scene(9, 9, 10, 0.004, 3000);
  ShapeSpec inclusion;
  inclusion.kind = ShapeSpec::Kind::Sphere;
  inclusion.center_m = Vec3(0.018, 0.018, 0.024);
  inclusion.radius_m = 0.008;
  inclusion.label = "stiff";
  s.model.shapes.push_back(inclusion);
  s.materials["stiff"] = material("stiff", 9000, 1000);
  ShapeSpec layer = s.model.shapes[0];
  layer.min_m.z() = 0.032;
  layer.label = "heavy";
  s.model.shapes.push_back(layer);
  s.materials["heavy"] = material("heavy", 3000, 1400);
  s.anchors.push_back(halfspace_anchor("base", Vec3(0, 0, 0.002), Vec3(0, 0, -1)));
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(9.81, 0, -9.81);
  s.solver.precision = Precision::Double;
  s.solver.integrator = integrator;
  s.solver.dashpot_ratio = integrator == Integrator::Relaxation ? 0 : 0.1;
  s.volume.preserve = volume;
  return s;
}

/// The hyperelastic validation tissues: neo-Hookean (E = 3 kPa) or, for law "ogden", two-term
/// Ogden (μ = 1200, −300 Pa; α = 4, −2); named "soft", ρ = 1000 kg/m³.
inline MaterialSpec validation_material(const std::string& law, double nu) {
  MaterialSpec m = material("soft", 3000, 1000);
  if (law == "ogden") {
    m.law = "ogden";
    m.ogden_mu_pa = {1200, -300};
    m.ogden_alpha = {4, -2};
  } else {
    m.law = "neo-hookean";
  }
  m.poisson_ratio = nu;
  return m;
}

/// mixed_block(Heun) with every tissue on the neo-Hookean law (ν = 0.45), each keeping its E and
/// density: the hyperelastic passes on the same kinds of neighbour.
inline Scene neo_hookean_mixed_block() {
  Scene s = mixed_block(Integrator::Heun, false);
  const MaterialSpec neo = validation_material("neo-hookean", 0.45);
  for (auto& [name, material] : s.materials) {
    material.law = neo.law;
    material.poisson_ratio = neo.poisson_ratio;
  }
  return s;
}

/// Two plates through the centres of the bottom and top layers of an n-layer box of spacing h
/// (so the gap is (n − 1)·h); the top one moves by (stretch − 1)·gap along z at `speed` and stops.
inline std::vector<IndenterSpec> plate_pair(int n, double h, double stretch,
                                            IndenterSpec::Contact contact = IndenterSpec::Contact::Push,
                                            double speed = 0.05) {
  const double gap = (n - 1) * h, travel = (stretch - 1) * gap;
  IndenterSpec base, top;
  base.kind = top.kind = IndenterSpec::Kind::Plate;
  base.contact = top.contact = contact;
  base.start_m = Vec3(0, 0, 0.5 * h);
  base.normal = Vec3(0, 0, 1);
  top.start_m = Vec3(0, 0, 0.5 * h + gap);
  top.normal = Vec3(0, 0, -1);
  top.velocity_m_s = Vec3(0, 0, travel > 0 ? speed : -speed);
  top.travel_time_s = std::abs(travel) / speed;
  return {base, top};
}

/// The stretch of the interior of an n-layer box along z, read between layers 1 and n − 2 like an
/// extensometer (the outer layers touch the plates): mean layer gap over (n − 3)·h.
inline double interior_stretch(const Lattice& lattice, const std::vector<double>& position_m, int n, double h) {
  double z_low = 0, z_high = 0;
  int count = 0;
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    const int k = lattice.voxel_ijk(e)[2];
    if (k == 1) z_low += position_m[3 * e + 2], ++count;
    if (k == n - 2) z_high += position_m[3 * e + 2];
  }
  return (z_high - z_low) / count / ((n - 3) * h);
}

struct Model {
  Lattice lattice;
  ElementArrays elements;
};

inline Model make_model(const Scene& s) {
  Model m;
  m.lattice = build_lattice(voxelise_shapes(s), s.model.downsample);
  m.elements = make_element_arrays(s, m.lattice);
  return m;
}

/// Every element's u then v as the simulator holds them now: one vector, for comparisons to the bit.
inline std::vector<double> state_uv(Simulator& sim) {
  std::vector<double> u, v;
  sim.download(u, v);
  u.insert(u.end(), v.begin(), v.end());
  return u;
}

/// How many values of a and b differ (compared to the bit); a value only one of them has differs.
inline std::size_t differing_values(const std::vector<double>& a, const std::vector<double>& b) {
  std::size_t differ = a.size() > b.size() ? a.size() - b.size() : b.size() - a.size();
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) differ += a[i] != b[i];
  return differ;
}

}  // namespace vb::test
