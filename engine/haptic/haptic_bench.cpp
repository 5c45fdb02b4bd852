#include "engine/haptic/haptic_bench.hpp"

#include <cmath>

namespace vb {
namespace {
constexpr double kSpacing = 0.002, kProbeRadius = 0.005, kDepth = 0.003;  // 3 mm: a 4 mm press folds the lattice (VALIDATION.md)
}

Scene haptic_bench_scene(std::size_t elements, Precision precision) {
  const int n = std::max(4, int(std::lround(std::cbrt(double(elements)))));
  const double h = kSpacing;
  Scene s;
  s.source_path = "haptic bench block";
  s.model.spacing_m = h;
  ShapeSpec box;
  box.kind = ShapeSpec::Kind::Box;
  box.min_m = Vec3(0, 0, -h);  // one held layer below z = 0
  box.max_m = h * Vec3(n, n, n - 1);
  box.label = "soft";
  s.model.shapes.push_back(box);
  MaterialSpec soft;
  soft.name = "soft";
  soft.youngs_modulus_pa = 3000;
  soft.density_kg_m3 = 1000;
  s.materials["soft"] = soft;
  AnchorSpec base;
  base.name = "base";
  base.kind = AnchorSpec::Kind::HalfSpace;
  base.point_m = Vec3::Zero();
  base.normal = Vec3(0, 0, -1);
  s.anchors.push_back(base);
  IndenterSpec probe;
  probe.kind = IndenterSpec::Kind::Sphere;
  probe.radius_m = kProbeRadius;
  const double top = (n - 1.5) * h;  // centre of the top layer
  probe.start_m = Vec3(0.5 * n * h, 0.5 * n * h, top + kProbeRadius);
  s.indenters.push_back(probe);
  s.solver.integrator = Integrator::Relaxation;
  s.solver.dt_safety = 0.9;
  s.solver.precision = precision;
  s.solver.check_every = 20;
  return s;
}

ProbeTrajectory haptic_bench_press(const Scene& scene, double seconds) {
  const Vec3 start = scene.indenters.at(0).start_m, down = start - Vec3(0, 0, kDepth);
  ProbeTrajectory t;
  t.time_s = {0, seconds / 3, 2 * seconds / 3, seconds};
  t.position_m = {start, down, down, start};
  return t;
}

}  // namespace vb
