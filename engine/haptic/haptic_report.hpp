#pragma once
/// The haptic loop's outputs (docs/OUTPUTS.md, "voxbreast haptic"): the force log as CSV and the
/// rate/jitter summary as JSON. mm and ms at the file boundary, named in the fields.
#include <nlohmann/json.hpp>
#include <string>

#include "engine/haptic/haptic_loop.hpp"

namespace vb {

/// time_s,x_mm,y_mm,z_mm,fx_n,fy_n,fz_n,updates,min_det_f — one row per force output.
std::string haptic_log_csv(const HapticLoopResult& result);

/// The terminal warning for a run that folded the lattice (when and how deep, what to do);
/// empty when it did not fold.
std::string haptic_fold_warning(const HapticLoopResult& result);

/// Rate, interval statistics, update rate and the outcome (blow-up, fold monitor); `elements` the model size.
nlohmann::json haptic_summary_json(const HapticLoopResult& result, const HapticLoopOptions& options,
                                   const HapticProbe& probe, std::size_t elements);

}  // namespace vb
