#pragma once
// Quasi-static probing scenes for the tests: a block on a held base, one indenter, [probe] set.
#include "engine/probe/press_line.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb::test {

/// Box of nx×ny×nz voxels of spacing h (minimum corner at the origin) with its bottom layer held,
/// relaxed to equilibrium at every probe increment (solver.integrator = "relaxation").
inline Scene probe_block(int nx, int ny, int nz, double h, double E_pa) {
  Scene s = box_scene(nx, ny, nz, h, E_pa);
  s.anchors.push_back(halfspace_anchor("base", Vec3(0, 0, h), Vec3(0, 0, -1)));
  s.solver.integrator = Integrator::Relaxation;
  s.solver.dt_safety = 0.9;
  s.solver.check_every = 50;
  s.stop.equilibrium = 1e-6;
  s.stop.max_steps = 40000;
  return s;
}

/// A single vertical press (down, −z) at (x, y), starting where the indenter first touches.
inline ProbeSpec press_at(double x, double y, double depth, int steps) {
  ProbeSpec p;
  p.active = true;
  p.from_m = p.to_m = Vec3(x, y, 1.0);  // far above: the press starts at first contact
  p.direction = -Vec3::UnitZ();
  p.depth_m = depth;
  p.steps = steps;
  return p;
}

inline ProbeResult run_probe(const Scene& s) {
  const Model m = make_model(s);
  Simulator sim(s, m.lattice, m.elements, cl_context());
  return run_press_line(s, m.lattice, m.elements, sim);
}

}  // namespace vb::test
