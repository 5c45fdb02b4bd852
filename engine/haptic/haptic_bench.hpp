#pragma once
/// The haptic-rate benchmark model (docs/BENCHMARKS.md, "Haptic rate"): a block of soft tissue
/// (E = 3 kPa) on a held base, about `elements` elements at 2 mm spacing, with a sphere
/// probe (radius 5 mm) above the centre of its top face, relaxed quasi-statically; and a press:
/// down 3 mm (a 4 mm press folds the 2 mm lattice, docs/VALIDATION.md) in
/// the first third of the run, held, back up in the last third.
#include "engine/haptic/haptic_loop.hpp"
#include "engine/scene/scene.hpp"

namespace vb {

Scene haptic_bench_scene(std::size_t elements, Precision precision);
ProbeTrajectory haptic_bench_press(const Scene& scene, double seconds);

}  // namespace vb
