// Heun's whole step as one launch with grid barriers (kernels/persistent.cl) against one launch per
// pass. Runs on NVIDIA GPUs only (VOXBREAST_DEVICE=gpu, scripts/perf_gpu.sh); elsewhere the
// persistent step is not offered and those tests skip. The launch's group count from the build
// log is checked on the host, everywhere.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "engine/sim/kernel_tables.hpp"
#include "engine/sim/opencl_runtime.hpp"
#include "engine/sim/persistent_step.hpp"
#include "engine/sim/simulator.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"
#include "tests/engine/sim/trajectory_compare.hpp"

namespace vb {
namespace {

enum class Case { SpringsVolume, OgdenVolumeEveryThird, OgdenPlates };

Scene make_case(Case c) {
  if (c == Case::OgdenPlates) {  // a moving plate: the stage times t0, t1 reach the contact
    Scene s = test::box_scene(8, 8, 8, 0.002, 3000);
    s.materials["soft"] = test::validation_material("ogden", 0.45);
    s.indenters = test::plate_pair(8, 0.002, 0.9);
    s.solver.precision = Precision::Double;
    s.solver.dashpot_ratio = 0.1;
    return s;
  }
  Scene s = test::box_scene(10, 10, 11, 0.005, 3000);
  if (c == Case::OgdenVolumeEveryThird) s.materials["soft"] = test::validation_material("ogden", 0.45);
  s.volume.preserve = true;
  s.volume.every = c == Case::OgdenVolumeEveryThird ? 3 : 1;
  // the one-launch step projects the predicted stage (kernels/persistent.cl): so must the passes
  s.volume.predictor = VolumeSpec::Predictor::Projection;
  s.anchors.push_back(test::halfspace_anchor("base", Vec3(0, 0, 0.0025), Vec3(0, 0, -1)));
  s.gravity.active = true;
  s.gravity.acceleration_m_s2 = Vec3(0, 0, -9.81);
  s.solver.precision = Precision::Double;
  s.solver.dashpot_ratio = 0.1;
  return s;
}

/// u then v after 150 Heun steps from rest with checks after steps 50 and 100 (and gravity turned
/// after step 50 where the scene has it: set_gravity must reach the persistent kernel), the step as one
/// launch (`persistent`, PlanOverrides::persistent) or one launch per pass; empty when the device
/// has no persistent step.
std::vector<double> run_case(Case c, bool persistent, int split = 0, int group_limit = 0) {
  const Scene s = make_case(c);
  const test::Model m = test::make_model(s);
  PlanOverrides o;
  o.persistent = persistent;
  if (split) o.force_split = split;
  if (group_limit) o.persistent_group_limit = std::size_t(group_limit);
  Simulator sim(s, m.lattice, m.elements, test::cl_context(), o);
  if (sim.persistent_step() != persistent) return {};
  for (int k = 0; k < 3; ++k) {
    sim.advance(50);
    if (k < 2) EXPECT_EQ(sim.check().nonfinite_elements, 0);
    if (k == 0 && s.gravity.active) sim.set_gravity(Vec3(0, 4.9, -8.5));  // a posture change reaches both
  }
  std::vector<double> u, v;
  sim.download(u, v);
  u.insert(u.end(), v.begin(), v.end());
  return u;
}

// Every pass of the step in one launch: a pass that started before the previous one had finished
// everywhere (a missing or leaky grid barrier), a stale cached read of another group's writes, a
// block of elements skipped or done twice, or a projection applied on the wrong steps would give
// another trajectory than one launch per pass. The same sums in the same order: equal to rounding.
TEST(PersistentStepGpu, MatchesOneLaunchPerPass) {
  const char* names[] = {"springs + volume", "two-term Ogden + volume every third step", "two-term Ogden + moving plate"};
  int k = 0;
  for (const Case c : {Case::SpringsVolume, Case::OgdenVolumeEveryThird, Case::OgdenPlates}) {
    const std::vector<double> one = run_case(c, true);
    if (one.empty()) GTEST_SKIP() << "no persistent step on this device (NVIDIA GPUs only)";
    const double d = test::relative_difference(one, run_case(c, false));
    std::cout << names[k] << ": persistent vs one launch per pass, largest difference over largest |u|, |v|: " << d
              << "\n";
    EXPECT_LE(d, 1e-12) << names[k];
    ++k;
  }
}

// The force passes' blocks with one, two and four work-items per element (VB_SPLIT), with 3
// work-groups in all, so that each walks several blocks of every pass (1,100 elements: 9 to 35
// blocks, about 9 volume groups): a block skipped or done twice, or a group's local memory reused by its
// next block before it was read, would give another trajectory.
TEST(PersistentStepGpu, MatchesWithEveryForceSplitAndFewGroups) {
  for (const int split : {1, 2, 4}) {
    const std::vector<double> one = run_case(Case::OgdenVolumeEveryThird, true, split, 3);
    if (one.empty()) GTEST_SKIP() << "no persistent step on this device (NVIDIA GPUs only)";
    EXPECT_LE(test::relative_difference(one, run_case(Case::OgdenVolumeEveryThird, false, split)), 1e-12) << split;
  }
}

// The one-launch step's kernel runs on NVIDIA GPUs only, so a change to a helper it shares with the
// separate kernels (a parameter added to predict_element) could leave it unbuildable without any
// CPU test noticing: it did once (the lagged pressure's new parameter), and every spring model stepping
// with Heun on a GPU failed to build. Here each case's program is built again as the GPU would
// build it, with the one-launch step compiled in (not launched: PoCL's groups are not co-resident),
// with one and two work-items per element. Runs everywhere.
TEST(PersistentStep, KernelBuildsOnEveryDevice) {
  for (const Case c : {Case::SpringsVolume, Case::OgdenVolumeEveryThird, Case::OgdenPlates})
    for (const int split : {1, 2}) {
      const Scene s = make_case(c);
      const test::Model m = test::make_model(s);
      PlanOverrides o;
      o.force_split = split;
      const auto sim = std::make_unique<Simulator>(s, m.lattice, m.elements, test::cl_context(), o);
      std::string options = sim->build_options();
      const std::string off = "-DVB_PERSISTENT=0";
      const std::size_t at = options.find(off);
      if (at != std::string::npos) options.replace(at, off.size(), "-DVB_PERSISTENT=1 -DVB_PERSISTENT_TRACE=0");
      ASSERT_NE(options.find("-DVB_PERSISTENT=1"), std::string::npos) << options;
      EXPECT_NO_THROW(build_program(test::cl_context(), sim->kernel_files(), lattice_tables_source(), options))
          << "case " << int(c) << ", split " << split;
    }
}

// The groups launched must all be resident: NVIDIA's compiler can use more registers than the
// plan's cap (96 against 80 for the double step at 125k elements, where 6 planned groups per
// compute unit did not fit and the grid barrier timed out), so the simulator reads the registers
// from the build log (ptxas's own lines, as NVIDIA's OpenCL 3.0 driver 580 writes them) and
// launches no more groups than fit. Host-only: runs everywhere.
TEST(PersistentStep, GroupsFitTheRegistersTheBuildLogReports) {
  const std::string log =
      "ptxas info    : Compiling entry function 'heun_predict' for 'sm_90a'\n"
      "ptxas info    : Function properties for heun_predict\n"
      "ptxas         .     0 bytes stack frame, 0 bytes spill stores, 0 bytes spill loads\n"
      "ptxas info    : Used 56 registers, used 1 barriers, 3076 bytes smem\n"
      "ptxas info    : Compiling entry function 'check_state' for 'sm_90a'\n"
      "ptxas info    : Function properties for check_state\n"
      "ptxas info    : Compiling entry function 'heun_step_persistent' for 'sm_90a'\n"
      "ptxas info    : Function properties for heun_step_persistent\n"
      "ptxas         .     0 bytes stack frame, 0 bytes spill stores, 0 bytes spill loads\n"
      "ptxas info    : Used 96 registers, used 1 barriers\n";
  EXPECT_EQ(registers_in_build_log(log, "heun_step_persistent"), 96);
  EXPECT_EQ(registers_in_build_log(log, "heun_predict"), 56);
  EXPECT_EQ(registers_in_build_log(log, "check_state"), -1) << "its entry has no Used line before the next entry";
  EXPECT_EQ(registers_in_build_log(log, "heun_correct"), -1);
  EXPECT_EQ(registers_in_build_log("", "heun_step_persistent"), -1);

  EXPECT_EQ(groups_per_unit_by_registers(64, 128), 8u);
  EXPECT_EQ(groups_per_unit_by_registers(80, 128), 6u);
  EXPECT_EQ(groups_per_unit_by_registers(96, 128), 5u);  // the double step that timed out with 6
  EXPECT_EQ(groups_per_unit_by_registers(81, 128), 5u);  // allocated as 88
  EXPECT_EQ(groups_per_unit_by_registers(255, 128), 2u);

  // the H200's 132 compute units, 6 groups per unit planned (125k elements)
  PersistentPlan plan;
  plan.on = true;
  plan.groups = 792;
  plan.fit_registers(64, 132);
  EXPECT_EQ(plan.groups, 792u) << "within the cap: the plan stays";
  plan.fit_registers(-1, 132);
  EXPECT_EQ(plan.groups, 792u) << "a log without the line: the plan stays";
  plan.fit_registers(96, 132);
  EXPECT_EQ(plan.groups, 660u) << "96 registers: 5 groups per unit";
}

}  // namespace
}  // namespace vb
