#pragma once
// A small fit problem built in code: a 10×10×8 box of soft tissue (4 mm voxels) with a stiff
// 4×4×3 inclusion ("tumour"), its bottom layer held, relaxed from gravity along +y to gravity
// along −y (a posture change that shears the inclusion), double precision.
#include "engine/fit/fit_regions.hpp"
#include "engine/fit/fit_spec.hpp"
#include "engine/lattice/voxelise.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb::test {

inline constexpr double kFitSpacing = 0.004;

/// Scene of the fit fixture: soft tissue `soft` (3 kPa linear unless replaced) and `tumour`.
inline Scene fit_box_scene(const MaterialSpec& soft, const MaterialSpec& tumour) {
  const double h = kFitSpacing;
  Scene s = box_scene(10, 10, 8, h);
  ShapeSpec inclusion = s.model.shapes[0];
  inclusion.min_m = h * Vec3(3, 3, 3);
  inclusion.max_m = h * Vec3(7, 7, 6);
  inclusion.label = "tumour";
  s.model.shapes.push_back(inclusion);
  s.materials["soft"] = soft;
  s.materials["soft"].name = "soft";
  s.materials["tumour"] = tumour;
  s.materials["tumour"].name = "tumour";
  s.anchors.push_back(halfspace_anchor("base", Vec3(0, 0, 0.5 * h), Vec3(0, 0, -1)));
  s.solver.integrator = Integrator::Relaxation;
  s.solver.dt_safety = 0.9;
  s.solver.precision = Precision::Double;
  s.solver.check_every = 10;
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, -9.81, 0);
  return s;
}

inline FitSpec fit_box_spec() {
  FitSpec f;
  f.from_gravity_m_s2 = Vec3(0, 9.81, 0);
  f.tissues = {"soft", "tumour"};
  return f;
}

}  // namespace vb::test
