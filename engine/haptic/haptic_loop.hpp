#pragma once
/// The haptic loop without hardware: a scripted probe trajectory is played in real time, the
/// probe's force read at a fixed rate (a deadline per period, decoupled from the deformation
/// updates), and every output logged with its timing (docs/HAPTICS.md).
#include <cstdint>
#include <string>
#include <vector>

#include "engine/haptic/haptic_probe.hpp"

namespace vb {

/// Probe positions at times, linear in between, held before the first and after the last.
struct ProbeTrajectory {
  std::vector<double> time_s;    ///< strictly increasing, ≥ 0
  std::vector<Vec3> position_m;  ///< world (m)
  Vec3 at(double t_s) const;
  double end_s() const { return time_s.empty() ? 0 : time_s.back(); }
};

/// From rows (time_s, x_mm, y_mm, z_mm); throws vb::Error naming `source` and the row for
/// times that do not increase or are negative.
ProbeTrajectory trajectory_from_rows(const std::vector<std::vector<double>>& rows, const std::string& source);

struct HapticLoopOptions {
  double rate_hz = 1000;  ///< force outputs per second
  double seconds = 0;     ///< how long to run; 0: to the trajectory's end
  /// run the output loop at real-time priority (SCHED_FIFO) when the system allows it, as a
  /// haptic driver would; it sleeps between outputs, so the update thread still gets the CPU
  bool realtime = true;
};

struct HapticSample {
  double time_s = 0;          ///< since the loop started (wall clock)
  Vec3 probe_m = Vec3::Zero();  ///< commanded probe position (m)
  Vec3 force_n = Vec3::Zero();  ///< force output (N)
  std::int64_t updates = 0;   ///< deformation updates done when it was output
  double min_det_f = 1;       ///< smallest det F of the free elements at the last fold check
};

/// Wall-clock intervals between consecutive outputs (s).
struct IntervalStats {
  double mean_s = 0, p50_s = 0, p99_s = 0, max_s = 0, stddev_s = 0;
  std::int64_t missed = 0;  ///< intervals longer than 1.5 periods
};
IntervalStats interval_stats(const std::vector<double>& intervals_s, double period_s);

struct HapticLoopResult {
  std::vector<HapticSample> samples;
  IntervalStats intervals;
  double achieved_rate_hz = 0;  ///< outputs per second over the run
  double wall_s = 0;
  std::int64_t updates = 0;     ///< deformation updates during the loop
  double update_rate_hz = 0;
  std::int64_t steps = 0;       ///< time steps during the loop
  bool blown_up = false;
  std::string message;          ///< the blow-up, when blown_up
  bool realtime = false;        ///< the output loop ran at real-time priority
  // The fold monitor (HapticUpdate's fold fields, over the whole run, a last check after it).
  bool folded = false;          ///< some check found a free element with det F ≤ 0: the force is not the tissue's
  double min_det_f = 1;         ///< smallest det F over the checks
  double first_fold_time_s = -1;  ///< loop time at which the output loop first saw the fold (−1: never)
  std::int64_t first_fold_update = -1;  ///< the probe's update count at the first folded check
  std::int64_t fold_checks = 0, folded_checks = 0;
  double fold_check_wall_s = 0;  ///< wall time of the checks (deformation thread)
};

/// Starts the probe's update thread, plays the trajectory for the run's length and stops it.
/// A blow-up ends the loop early (blown_up, message); the samples so far are kept. A fold does
/// not: the run goes on and `folded` says so (the output loop only reads the probe's flag).
HapticLoopResult run_haptic_loop(HapticProbe& probe, const ProbeTrajectory& trajectory, const HapticLoopOptions& options);

}  // namespace vb
