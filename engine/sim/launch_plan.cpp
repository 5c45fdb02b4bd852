#include "engine/sim/launch_plan.hpp"

#include <algorithm>
#include <charconv>
#include <sstream>

#include "engine/error.hpp"
#include "engine/sim/correct_order.hpp"
#include "engine/sim/kernel_arg_layout.hpp"
#include "engine/sim/opencl_runtime.hpp"
#include "engine/sim/step_list_rule.hpp"
#include "engine/sim/step_work_group.hpp"
#include "engine/sim/uniform_neighbourhood.hpp"

namespace vb {
namespace {

std::size_t parse_size(const std::string& key, const std::string& value) {
  std::size_t n = 0;
  const auto [last, ec] = std::from_chars(value.data(), value.data() + value.size(), n);
  require(ec == std::errc() && last == value.data() + value.size(),
          "plan override '" + key + "=" + value + "' is not a whole number", "--plan");
  return n;
}

bool parse_flag(const std::string& key, const std::string& value) {
  require(value == "0" || value == "1", "plan override '" + key + "=" + value + "' must be 0 or 1", "--plan");
  return value == "1";
}

}  // namespace

PlanInputs plan_inputs(const Scene& scene, bool hyperelastic, bool biphasic, std::size_t elements, std::size_t held,
                       bool triangle_contact, const DeviceInfo& device, std::size_t max_work_group) {
  PlanInputs in;
  in.gpu = device.is_gpu;
  in.nvidia_ptx = nvidia_ptx(device);
  in.compute_units = device.compute_units;
  in.max_work_group = max_work_group;
  in.integrator = scene.solver.integrator;
  in.precision = scene.solver.precision;
  in.hyperelastic = hyperelastic;
  in.biphasic = biphasic;
  in.rest_offsets = scene.reference_state.active;
  in.volume = scene.volume.preserve;
  in.volume_pressure_predictor = scene.volume.predictor == VolumeSpec::Predictor::Pressure;
  in.volume_every = scene.volume.every;
  in.indenters = !scene.indenters.empty();
  in.tori = !scene.tori.empty();
  in.triangle_contact = triangle_contact;
  in.elements = elements;
  in.held = held;
  return in;
}

PlanOverrides PlanOverrides::parse(const std::string& text) {
  PlanOverrides o;
  std::stringstream items(text);
  std::string item;
  while (std::getline(items, item, ',')) {
    if (item.empty()) continue;
    const std::size_t eq = item.find('=');
    require(eq != std::string::npos, "plan override '" + item + "' is not key=value", "--plan");
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "volume_launches") {
      const std::size_t k = parse_size(key, value);
      require(k <= 2, "plan override volume_launches must be 0, 1 or 2", "--plan");
      o.volume_launches = int(k);
    } else if (key == "force_split") {
      const std::size_t k = parse_size(key, value);
      require(k == 1 || k == 2 || k == 4, "plan override force_split must be 1, 2 or 4", "--plan");
      o.force_split = int(k);
    } else if (key == "lanes") {
      o.lanes = parse_flag(key, value);
    } else if (key == "persistent") {
      o.persistent = parse_flag(key, value);
    } else if (key == "step_list") {
      o.step_list = parse_flag(key, value);
    } else if (key == "correct_reverse") {
      o.correct_reverse = parse_flag(key, value);
    } else if (key == "uniform_path") {
      o.uniform_path = parse_flag(key, value);
    } else if (key == "pred_packed") {
      o.pred_packed = parse_flag(key, value);
    } else if (key == "stress_pair") {
      o.stress_pair = parse_flag(key, value);
    } else if (key == "volume_pairs") {
      o.volume_pairs = parse_flag(key, value);
    } else if (key == "step_work_group") {
      o.step_work_group = parse_size(key, value);
    } else if (key == "persistent_groups_per_unit") {
      o.persistent_groups_per_unit = std::clamp<std::size_t>(parse_size(key, value), 1, 8);
    } else if (key == "persistent_group_limit") {
      o.persistent_group_limit = std::max<std::size_t>(parse_size(key, value), 1);
    } else if (key == "persistent_trace") {
      o.persistent_trace = parse_flag(key, value);
    } else {
      throw Error("unknown plan override '" + key + "'", "--plan",
                  "one of volume_launches, force_split, lanes, persistent, step_list, correct_reverse, uniform_path, "
                  "pred_packed, stress_pair, volume_pairs, step_work_group, persistent_groups_per_unit, "
                  "persistent_group_limit, persistent_trace");
    }
  }
  return o;
}

bool PlanOverrides::empty() const {
  return !volume_launches && !force_split && !lanes && !persistent && !step_list && !correct_reverse &&
         !uniform_path && !pred_packed && !stress_pair && !volume_pairs && !step_work_group &&
         !persistent_groups_per_unit && !persistent_group_limit && !persistent_trace;
}

LaunchPlan choose_launch_plan(const PlanInputs& in, const PlanOverrides& o) {
  LaunchPlan p;
  const bool heun = in.integrator == Integrator::Heun, relax = in.integrator == Integrator::Relaxation;
  if (in.volume) {
    // a projection is two launches on GPUs (volume_partials, volume_apply: the one-launch form's
    // last group, applying the projection alone, is the longer), one elsewhere (volume_project);
    // folded (0: the kernels that read the state next apply the pending projection) only when asked,
    // for Heun, and not with triangle contact (which reads the state without a pending projection)
    p.volume_launches = in.gpu ? 2 : 1;
    if (o.volume_launches) {
      const int k = *o.volume_launches;
      if (k == 1 || k == 2) p.volume_launches = k;
      if (k == 0 && heun && !in.triangle_contact) p.volume_launches = 0;
    }
  }
  const bool folded = p.folded();
  p.force_split = heun && in.gpu && in.hyperelastic && in.elements <= kSplitMaxElements ? 2 : 1;
  if (o.force_split && heun) p.force_split = *o.force_split;
  p.lanes = !in.gpu && in.precision == Precision::Float && !in.hyperelastic && !in.biphasic && !in.indenters &&
            !in.tori && !in.triangle_contact && !folded && !in.rest_offsets && p.force_split == 1;
  if (o.lanes) p.lanes = p.lanes && *o.lanes;

  // Heun's whole step in one launch on NVIDIA (persistent_step.hpp): not with triangle contact (its
  // own pass) or folded projections (another way to fewer launches)
  const bool persistent_possible = heun && !in.triangle_contact && !folded && in.nvidia_ptx && in.compute_units > 0;
  PersistentPlan& ps = p.persistent;
  ps.on = persistent_possible && !in.hyperelastic && in.elements <= kPersistentMaxElements;
  if (o.persistent) ps.on = persistent_possible && *o.persistent;
  if (ps.on) {
    constexpr std::size_t kMinPerUnit = 2, kMaxPerUnit = 6;
    const std::size_t per_block = PersistentPlan::kWorkGroup / std::size_t(std::max(p.force_split, 1));
    const std::size_t blocks = (in.elements + per_block - 1) / per_block;
    std::size_t per_unit = std::clamp((blocks + in.compute_units - 1) / in.compute_units, kMinPerUnit, kMaxPerUnit);
    if (o.persistent_groups_per_unit) per_unit = *o.persistent_groups_per_unit;
    ps.trace = o.persistent_trace;
    ps.groups = per_unit * in.compute_units;
    if (o.persistent_group_limit) ps.groups = std::min(*o.persistent_group_limit, ps.groups);
    ps.max_registers = persistent_register_cap(per_unit);
  }

  const bool list_allowed = !p.lanes && p.force_split == 1 && !ps.on;
  p.step_list = list_allowed && default_step_list(in.gpu, in.elements, in.held, relax && in.hyperelastic);
  if (o.step_list) p.step_list = list_allowed && *o.step_list;

  const bool reverse_allowed = heun && !p.lanes && p.force_split == 1 && !ps.on && !p.step_list;
  p.correct_reverse = reverse_allowed && default_correct_reverse(in.gpu, in.elements, in.volume);
  if (o.correct_reverse) p.correct_reverse = reverse_allowed && *o.correct_reverse;

  const bool uniform_allowed = !in.hyperelastic && !in.biphasic && !in.rest_offsets && !p.lanes && !ps.on;
  p.uniform_path = uniform_allowed && in.gpu && !p.step_list;
  if (o.uniform_path) p.uniform_path = uniform_allowed && *o.uniform_path;

  // Heun's predicted stage under the last correction's pressure (docs/PHYSICS.md, "Volume
  // preservation"), and relaxation's step; not between sparser projections, folded ones or in the
  // one-launch step (its own schedule)
  const bool lag_heun = heun && in.volume_pressure_predictor;
  p.volume_lag = in.volume && (lag_heun || relax) && in.volume_every == 1 && !folded && !ps.on;
  // both of Heun's element stresses in one launch: the predicted stage is u + dt·v whatever its force
  // unless indenters, tori or the stage's own projection move it
  p.stress_pair = in.hyperelastic && heun && !in.indenters && !in.tori && (!in.volume || p.volume_lag) && !folded &&
                  !ps.on;
  if (o.stress_pair) p.stress_pair = p.stress_pair && *o.stress_pair;
  p.volume_pairs = in.volume && o.volume_pairs.value_or(true);

  // one work-item per element (or listed element): 128 or 256 on GPUs, the runtime's choice on CPUs;
  // an override only where that is the layout (not the split pass or the lanes kernels)
  p.step_work_group = in.gpu ? default_step_work_group(in.elements) : 0;
  if (o.step_work_group && p.force_split == 1 && !p.lanes)
    p.step_work_group = checked_step_work_group(*o.step_work_group, in.max_work_group);
  return p;
}

bool choose_pred_packing(const LaunchPlan& p, const PlanInputs& in, std::size_t uniform_elements,
                         const PlanOverrides& o) {
  const bool allowed = in.integrator == Integrator::Heun && p.uniform_path && p.force_split == 1 && !p.persistent.on &&
                       !p.step_list && !p.lanes && !in.volume && !in.indenters && !in.tori && !in.triangle_contact;
  const bool packed = allowed && default_pred_packing(in.gpu, uniform_elements, in.elements - in.held);
  return o.pred_packed ? allowed && *o.pred_packed : packed;
}

std::string LaunchPlan::build_options(bool volume) const {
  std::string s;
  s += " -DVB_UNIFORM_PATH=" + std::to_string(uniform_path);
  s += " -DVB_PRED_PACKED=" + std::to_string(pred_packed);
  s += " -DVB_VOLUME_FOLD=" + std::to_string(volume && folded());
  s += " -DVB_SPLIT=" + std::to_string(force_split);
  s += " -DVB_LANES=" + std::to_string(lanes);
  s += persistent.options();
  s += " -DVB_VOLUME_LAG=" + std::to_string(volume_lag);
  s += " -DVB_STRESS_PAIR=" + std::to_string(stress_pair);
  if (volume) s += " -DVB_VOLUME_PAIRS=" + std::to_string(volume_pairs);
  return s;
}

std::vector<std::string> LaunchPlan::kernel_files(bool volume, bool relaxation) const {
  // device_contact.cl before lattice_forces.cl: the indenters' friction reuses its grip helpers
  std::vector<std::string> files = {"common.cl",         "hyperelastic.cl",     "device_contact.cl",
                                    "lattice_forces.cl", "triangle_contact.cl", "integrate.cl",
                                    "integrate_lanes.cl"};
  if (volume) files.push_back("volume.cl");
  files.push_back("persistent.cl");
  if (relaxation) files.push_back("relax.cl");
  files.push_back("checks.cl");
  return files;
}

}  // namespace vb
