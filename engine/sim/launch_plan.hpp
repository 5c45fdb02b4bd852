#pragma once
/// How a scene's step is launched: every schedule choice the simulator makes (which kernels, how many
/// work-items per element, which launches are folded together), chosen by one pure function from the
/// scene's features, the device and the model's size. The choices only change speed: every plan a
/// scene may take steps the same arithmetic, so trajectories agree to the bit between plans that
/// share their kernels' operation order (tests/engine/sim run the plans of every device on PoCL).
///
/// The rules, each measured on the device it is for (docs/PERFORMANCE.md gives the numbers):
///
/// | choice            | default                                                            | needs                                    |
/// |-------------------|--------------------------------------------------------------------|------------------------------------------|
/// | volume_launches   | 2 on GPUs, 1 elsewhere (0 = folded into the next pass: override)   | the volume constraint                    |
/// | force_split       | 2 on GPUs for hyperelastic Heun up to kSplitMaxElements (kernel_arg_layout.hpp), else 1 | Heun                                     |
/// | lanes             | on CPUs for plain float spring models                              | no contact, rest offsets, split, folding |
/// | persistent        | NVIDIA spring models up to kPersistentMaxElements (one launch)     | Heun, no triangle contact, no folding    |
/// | step_list         | GPUs above 65,536 elements with a quarter held (step_list_rule)    | no lanes, split or persistent step       |
/// | correct_reverse   | GPUs from 1,000,000 elements without the volume constraint         | Heun, one work-item per element, no list |
/// | uniform_path      | linear springs on GPUs without the step list                       | no biphasic, rest offsets, lanes, persist|
/// | pred_packed       | GPUs where the short loop takes half the free elements             | plain Heun on the short loop             |
/// | volume_lag        | Heun with the pressure predictor, or relaxation, projecting every step | not folded, not persistent           |
/// | stress_pair       | hyperelastic Heun without obstacles                                | not folded, not persistent               |
/// | volume_pairs      | on                                                                 | the volume constraint                    |
/// | step_work_group   | GPUs: 128, 256 from 131,072 elements; CPUs: the runtime's choice   | one work-item per element                |
///
/// Overrides (PlanOverrides) force a choice where its "needs" allow, to compare plans on a device
/// (`voxbreast bench --plan`) and to run a device's plan in tests; they never make a plan that
/// its kernels cannot run.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"
#include "engine/sim/persistent_step.hpp"

namespace vb {

struct DeviceInfo;

/// What the choice depends on: the scene's features, the device, the model's size.
struct PlanInputs {
  bool gpu = false;
  bool nvidia_ptx = false;            ///< inline PTX accepted (persistent_step.hpp)
  unsigned compute_units = 0;
  std::size_t max_work_group = 1024;  ///< CL_DEVICE_MAX_WORK_GROUP_SIZE
  Integrator integrator = Integrator::Heun;
  Precision precision = Precision::Double;
  bool hyperelastic = false, biphasic = false, rest_offsets = false;
  bool volume = false;                ///< the volume constraint
  bool volume_pressure_predictor = false;
  int volume_every = 1;
  bool indenters = false, tori = false, triangle_contact = false;
  std::size_t elements = 0, held = 0;
};

/// The inputs of a scene on a device (triangle contact as the simulator decided it).
PlanInputs plan_inputs(const Scene& scene, bool hyperelastic, bool biphasic, std::size_t elements,
                       std::size_t held, bool triangle_contact, const DeviceInfo& device, std::size_t max_work_group);

/// A choice forced where the plan's rules allow it; unset = the device's default.
struct PlanOverrides {
  std::optional<int> volume_launches;  ///< 0 (folded, Heun without triangle contact), 1 or 2
  std::optional<int> force_split;      ///< 1, 2 or 4 (Heun)
  std::optional<bool> lanes, persistent, step_list, correct_reverse, uniform_path, pred_packed, stress_pair,
      volume_pairs;
  std::optional<std::size_t> step_work_group;          ///< multiple of 32 up to the device's maximum
  std::optional<std::size_t> persistent_groups_per_unit;  ///< 1–8
  std::optional<std::size_t> persistent_group_limit;    ///< at most this many groups (each walks more blocks)
  bool persistent_trace = false;  ///< the one-launch step prints its pass times at each check (stderr)

  /// "key=value,key=value" with the keys above (booleans 0/1); throws vb::Error naming a bad key
  /// or value.
  static PlanOverrides parse(const std::string& text);
  bool empty() const;
};

struct LaunchPlan {
  int volume_launches = 1;  ///< per projection: 1 volume_project, 2 volume_partials + volume_apply, 0 folded
  int force_split = 1;      ///< work-items per element in Heun's force passes
  bool lanes = false;       ///< CPU kernels stepping 8 elements per work-item (kernels/integrate_lanes.cl)
  PersistentPlan persistent;  ///< Heun's whole step in one launch (kernels/persistent.cl)
  bool step_list = false;       ///< stepping kernels over a list of the free elements (VB_STEP_LIST)
  bool correct_reverse = false; ///< heun_correct over the blocks last to first (VB_CORRECT_REVERSE)
  bool uniform_path = false;    ///< linear springs: uniform neighbourhoods take a short loop
  bool pred_packed = false;     ///< Heun's predicted stage packed (VB_PRED_PACKED; choose_pred_packing)
  bool volume_lag = false;      ///< Heun's predicted stage (relaxation's step) under the lagged pressure
  bool stress_pair = false;     ///< Heun's two element stresses in one launch (VB_STRESS_PAIR)
  bool volume_pairs = true;     ///< the volume gradient's incident triangles as element pairs
  std::size_t step_work_group = 0;  ///< work-items per group of the stepping kernels; 0 = the runtime's

  bool folded() const { return volume_launches == 0; }
  /// the -D options of the plan's choices (the rest of the build options are the scene's features)
  std::string build_options(bool volume) const;
  /// the kernel files the plan's program is built from, in order
  std::vector<std::string> kernel_files(bool volume, bool relaxation) const;
};

/// The plan for `in`, with `overrides` applied where allowed. Pure: the same inputs give the same plan.
/// pred_packed is false here: it depends on the short loop's marks (choose_pred_packing).
LaunchPlan choose_launch_plan(const PlanInputs& in, const PlanOverrides& overrides = {});

/// Whether Heun's predicted stage is packed, once `uniform_elements` of the free elements are known
/// to take the short loop.
bool choose_pred_packing(const LaunchPlan& plan, const PlanInputs& in, std::size_t uniform_elements,
                         const PlanOverrides& overrides = {});

}  // namespace vb
