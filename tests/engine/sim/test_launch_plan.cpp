// The launch plan (engine/sim/launch_plan.hpp): the rules of its table as a pure function of the
// scene's features, the device and the model's size; overrides that apply only where a rule allows
// them; and every plan a device would choose, GPU plans included, run on the default device (PoCL in
// CI) against that device's own plan: the schedule must not change the trajectory.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "engine/error.hpp"
#include "engine/sim/kernel_arg_layout.hpp"
#include "engine/sim/launch_plan.hpp"
#include "engine/sim/simulator.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"
#include "tests/engine/sim/trajectory_compare.hpp"

namespace vb {
namespace {

/// An NVIDIA GPU with `units` compute units (an H100 has 132) or a CPU device, for a model of
/// `elements` of which `held` are held.
PlanInputs device_inputs(bool nvidia, std::size_t elements, std::size_t held = 0, unsigned units = 132) {
  PlanInputs in;
  in.gpu = nvidia;
  in.nvidia_ptx = nvidia;
  in.compute_units = nvidia ? units : 2;
  in.max_work_group = nvidia ? 1024 : 4096;
  in.elements = elements;
  in.held = held;
  return in;
}

TEST(LaunchPlan, CpuFloatSpringsTakeTheLanesKernels) {
  PlanInputs in = device_inputs(false, 36000);
  in.precision = Precision::Float;
  const LaunchPlan p = choose_launch_plan(in);
  EXPECT_TRUE(p.lanes);
  EXPECT_FALSE(p.persistent.on);
  EXPECT_EQ(p.force_split, 1);
  EXPECT_EQ(p.step_work_group, 0u);  // PoCL picks
  in.precision = Precision::Double;
  EXPECT_FALSE(choose_launch_plan(in).lanes);
  in.precision = Precision::Float;
  in.indenters = true;  // the lanes kernels have no contact
  EXPECT_FALSE(choose_launch_plan(in).lanes);
}

TEST(LaunchPlan, SmallNvidiaSpringModelsStepInOneLaunch) {
  PlanInputs in = device_inputs(true, kPersistentMaxElements);
  LaunchPlan p = choose_launch_plan(in);
  EXPECT_TRUE(p.persistent.on);
  EXPECT_GE(p.persistent.groups, 2u * 132);
  EXPECT_LE(p.persistent.groups, 6u * 132);
  EXPECT_FALSE(p.step_list);
  EXPECT_FALSE(p.uniform_path);  // its second loop overflows the one-launch step's register cap
  in.elements = kPersistentMaxElements + 1;
  p = choose_launch_plan(in);
  EXPECT_FALSE(p.persistent.on);
  EXPECT_TRUE(p.uniform_path);
  in.triangle_contact = true;  // its own pass
  in.elements = 1000;
  EXPECT_FALSE(choose_launch_plan(in).persistent.on);
}

TEST(LaunchPlan, SmallHyperelasticHeunSplitsOnGpus) {
  PlanInputs in = device_inputs(true, kSplitMaxElements);
  in.hyperelastic = true;
  LaunchPlan p = choose_launch_plan(in);
  EXPECT_EQ(p.force_split, 2);
  EXPECT_FALSE(p.persistent.on);
  EXPECT_TRUE(p.stress_pair);
  in.elements = kSplitMaxElements + 1;
  EXPECT_EQ(choose_launch_plan(in).force_split, 1);
  in.integrator = Integrator::Relaxation;
  in.elements = 1000;
  p = choose_launch_plan(in);
  EXPECT_EQ(p.force_split, 1);
  EXPECT_FALSE(p.stress_pair);
}

TEST(LaunchPlan, LargeGpuModelsTakeTheListAndLargeGroups) {
  const LaunchPlan p = choose_launch_plan(device_inputs(true, 1500000, 1000000));
  EXPECT_TRUE(p.step_list);
  EXPECT_FALSE(p.correct_reverse);  // not with the list
  EXPECT_FALSE(p.uniform_path);     // off by default with the list
  EXPECT_EQ(p.step_work_group, 256u);
  const LaunchPlan few_held = choose_launch_plan(device_inputs(true, 1500000, 1000));
  EXPECT_FALSE(few_held.step_list);
  EXPECT_TRUE(few_held.correct_reverse);
}

TEST(LaunchPlan, VolumeProjectionLaunchesByDevice) {
  PlanInputs in = device_inputs(false, 5000);
  in.volume = true;
  in.volume_pressure_predictor = true;
  EXPECT_EQ(choose_launch_plan(in).volume_launches, 1);
  EXPECT_TRUE(choose_launch_plan(in).volume_lag);
  in.gpu = true;
  EXPECT_EQ(choose_launch_plan(in).volume_launches, 2);
  in.volume_every = 3;  // no multiplier to lag between sparser projections
  EXPECT_FALSE(choose_launch_plan(in).volume_lag);
}

TEST(LaunchPlan, OverridesApplyOnlyWhereTheRulesAllow) {
  PlanInputs in = device_inputs(false, 5000);
  in.precision = Precision::Float;
  PlanOverrides o;
  o.force_split = 4;
  o.step_list = true;
  LaunchPlan p = choose_launch_plan(in, o);
  EXPECT_EQ(p.force_split, 4);
  EXPECT_FALSE(p.lanes);     // the lanes kernels have no split pass
  EXPECT_FALSE(p.step_list); // nor does the list
  o = {};
  o.persistent = true;       // a CPU has no inline PTX
  EXPECT_FALSE(choose_launch_plan(in, o).persistent.on);
  in.integrator = Integrator::Relaxation;
  o = {};
  o.force_split = 2;         // Heun only
  EXPECT_EQ(choose_launch_plan(in, o).force_split, 1);
  in.integrator = Integrator::Heun;
  in.volume = true;
  in.triangle_contact = true;
  o = {};
  o.volume_launches = 0;     // folding is not for triangle contact
  EXPECT_EQ(choose_launch_plan(in, o).volume_launches, 1);
}

TEST(LaunchPlan, OverridesParseAndRefuseByName) {
  const PlanOverrides o = PlanOverrides::parse("lanes=0,step_list=1,force_split=4,step_work_group=64");
  ASSERT_TRUE(o.lanes && o.step_list && o.force_split && o.step_work_group);
  EXPECT_FALSE(*o.lanes);
  EXPECT_TRUE(*o.step_list);
  EXPECT_EQ(*o.force_split, 4);
  EXPECT_EQ(*o.step_work_group, 64u);
  EXPECT_TRUE(PlanOverrides::parse("").empty());
  for (const char* bad : {"lane=0", "lanes=2", "force_split=3", "volume_launches=5", "step_work_group=x", "lanes"}) {
    try {
      PlanOverrides::parse(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const Error& e) {
      const std::string what = e.what(), key = std::string(bad).substr(0, std::string(bad).find('='));
      EXPECT_NE(what.find(key), std::string::npos) << what;
    }
  }
}

TEST(LaunchPlan, BuildOptionsFollowThePlan) {
  PlanInputs in = device_inputs(true, 36000);
  in.hyperelastic = true;
  const LaunchPlan p = choose_launch_plan(in);
  const std::string options = p.build_options(false);
  EXPECT_NE(options.find("-DVB_SPLIT=2"), std::string::npos) << options;
  EXPECT_NE(options.find("-DVB_STRESS_PAIR=1"), std::string::npos) << options;
  EXPECT_EQ(options.find("VB_VOLUME_PAIRS"), std::string::npos) << options;
  const std::vector<std::string> files = p.kernel_files(true, true);
  EXPECT_EQ(files.front(), "common.cl");
  EXPECT_EQ(files.back(), "checks.cl");
  EXPECT_NE(std::find(files.begin(), files.end(), "volume.cl"), files.end());
  EXPECT_NE(std::find(files.begin(), files.end(), "relax.cl"), files.end());
}

// ---- every GPU plan on the default device --------------------------------------------------------

/// The overrides that make a simulator take `p` (the one-launch step left out: its work-groups
/// wait for each other, which needs a device that keeps them all resident; PersistentStep's tests
/// build it everywhere and run it on NVIDIA).
PlanOverrides overrides_of(const LaunchPlan& p) {
  PlanOverrides o;
  o.volume_launches = p.volume_launches;
  o.force_split = p.force_split;
  o.lanes = p.lanes;
  o.persistent = false;
  o.step_list = p.step_list;
  o.correct_reverse = p.correct_reverse;
  o.uniform_path = p.uniform_path;
  o.pred_packed = p.pred_packed;
  o.stress_pair = p.stress_pair;
  o.volume_pairs = p.volume_pairs;
  if (p.step_work_group) o.step_work_group = p.step_work_group;
  return o;
}

/// u then v after 120 steps (a check after 60) of `s` under `o`.
std::vector<double> steps_with(const Scene& s, const test::Model& m, const PlanOverrides& o, LaunchPlan* taken) {
  Simulator sim(s, m.lattice, m.elements, test::cl_context(), o);
  *taken = sim.launch_plan();
  sim.advance(60);
  EXPECT_EQ(sim.check().nonfinite_elements, 0);
  sim.advance(60);
  return test::state_uv(sim);
}

/// The plans an H100 (132 compute units) chooses for a scene at three model sizes: small (the
/// one-launch step or the split pass), mid-size with two thirds held (the step list), and large
/// with few held (the reversed corrector, groups of 256). Each distinct one is run once.
TEST(LaunchPlan, EveryGpuPlanStepsLikeTheDefaultPlan) {
  struct Size {
    std::size_t elements, held;
  };
  const Size sizes[] = {{36000, 12000}, {150000, 100000}, {1500000, 1000}};
  // springs with the volume constraint (projection launches, the list, the short loop, the reversed
  // corrector) and a hyperelastic law (the split pass, paired stresses); the other integrators'
  // schedules are compared pairwise in StepList, StepWorkGroup, UniformPath and VolumeConstraint
  const std::vector<Scene> scenes = {test::mixed_block(Integrator::Heun, true), test::neo_hookean_mixed_block()};
  for (const Scene& s : scenes) {
    const test::Model m = test::make_model(s);
    bool hyper = false;
    for (const auto& [name, material] : s.materials) hyper = hyper || material.law != "linear";
    LaunchPlan own;
    const std::vector<double> reference = steps_with(s, m, {}, &own);
    std::vector<std::string> seen = {own.build_options(s.volume.preserve) + std::to_string(own.step_work_group)};
    for (const Size& size : sizes) {
      PlanInputs gpu = plan_inputs(s, hyper, false, size.elements, size.held, false, test::cl_context().info, 1024);
      gpu.gpu = gpu.nvidia_ptx = true;
      gpu.compute_units = 132;
      const LaunchPlan wanted = choose_launch_plan(gpu);
      const PlanOverrides o = overrides_of(wanted);
      LaunchPlan taken;
      const std::string what = "integrator " + std::to_string(int(s.solver.integrator)) +
                               (s.volume.preserve ? ", volume" : "") + (hyper ? ", neo-Hookean" : "") + ", plan for " +
                               std::to_string(size.elements) + " elements";
      {
        // the plan the overrides give on this device, without running it: a repeat is not run again
        const Simulator probe(s, m.lattice, m.elements, test::cl_context(), o);
        taken = probe.launch_plan();
      }
      EXPECT_EQ(taken.force_split, wanted.force_split) << what;
      EXPECT_EQ(taken.step_list, wanted.step_list) << what;
      EXPECT_EQ(taken.uniform_path, wanted.uniform_path) << what;
      EXPECT_EQ(taken.stress_pair, wanted.stress_pair) << what;
      EXPECT_EQ(taken.correct_reverse, wanted.correct_reverse) << what;
      EXPECT_EQ(taken.volume_launches, wanted.volume_launches) << what;
      const std::string key = taken.build_options(s.volume.preserve) + std::to_string(taken.step_work_group);
      if (std::find(seen.begin(), seen.end(), key) != seen.end()) continue;
      seen.push_back(key);
      const std::vector<double> got = steps_with(s, m, o, &taken);
      EXPECT_LE(test::relative_difference(got, reference), 1e-12) << what;
    }
  }
}

}  // namespace
}  // namespace vb
