#pragma once
/// The standard study of `voxbreast bench`: which scenes at which sizes, and which knob
/// combinations on each (docs/BENCHMARKS.md, "Design"). --quick is the CI-sized version.
#include <string>
#include <vector>

#include "engine/bench/bench_design.hpp"
#include "engine/bench/bench_scenes.hpp"
#include "engine/bench/trade_study.hpp"

namespace vb::bench {

struct PlanOptions {
  bool quick = false;
  bool large = false;                     ///< add "phantom_large", the phantom resampled to ~1.5M elements
  std::string phantom_scene;              ///< the phantom's scene.toml; "" leaves the phantom scenes out
  std::vector<std::string> scenes;        ///< only these scenes (empty: all)
  std::vector<std::string> laws;          ///< the grid's laws (empty: all; --quick: all but Ogden)
  std::vector<std::string> integrators;   ///< only these integrators (empty: all)
};

struct StudyPlan {
  std::vector<BenchScene> scenes;
  std::vector<BenchCase> cases;  ///< in run order; each case's reference runs before it
  StudySettings settings;
};

/// Scene names of the standard study, in run order.
std::vector<std::string> standard_scene_names();

/// Builds the scenes (reads the phantom CT) and the design. Throws vb::Error for an unknown
/// scene, law or integrator name.
StudyPlan standard_plan(const PlanOptions& options);

}  // namespace vb::bench
