#include "engine/haptic/haptic_loop.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <pthread.h>
#include <sched.h>
#include <thread>

#include "engine/error.hpp"

namespace vb {

Vec3 ProbeTrajectory::at(double t) const {
  require(!time_s.empty(), "the probe trajectory is empty");
  if (t <= time_s.front()) return position_m.front();
  if (t >= time_s.back()) return position_m.back();
  const std::size_t j = std::size_t(std::upper_bound(time_s.begin(), time_s.end(), t) - time_s.begin());
  const double w = (t - time_s[j - 1]) / (time_s[j] - time_s[j - 1]);
  return (1 - w) * position_m[j - 1] + w * position_m[j];
}

ProbeTrajectory trajectory_from_rows(const std::vector<std::vector<double>>& rows, const std::string& source) {
  ProbeTrajectory t;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const auto& row = rows[r];
    require(row.size() == 4, "a trajectory row has time_s, x_mm, y_mm, z_mm", source);
    const std::string where = source + " (row " + std::to_string(r + 1) + ")";
    require(row[0] >= 0, "time_s is negative", where);
    require(t.time_s.empty() || row[0] > t.time_s.back(), "time_s does not increase", where,
            "list the trajectory's points in time order, each time once");
    t.time_s.push_back(row[0]);
    t.position_m.push_back(1e-3 * Vec3(row[1], row[2], row[3]));
  }
  return t;
}

IntervalStats interval_stats(const std::vector<double>& intervals, double period_s) {
  IntervalStats s;
  if (intervals.empty()) return s;
  std::vector<double> sorted(intervals);
  std::sort(sorted.begin(), sorted.end());
  double sum = 0, sum_sq = 0;
  for (double x : intervals) sum += x, sum_sq += x * x;
  const double n = double(intervals.size());
  s.mean_s = sum / n;
  s.stddev_s = std::sqrt(std::max(0.0, sum_sq / n - s.mean_s * s.mean_s));
  const auto quantile = [&](double q) { return sorted[std::min(sorted.size() - 1, std::size_t(q * n))]; };
  s.p50_s = quantile(0.5);
  s.p99_s = quantile(0.99);
  s.max_s = sorted.back();
  s.missed = std::count_if(intervals.begin(), intervals.end(), [&](double x) { return x > 1.5 * period_s; });
  return s;
}

namespace {

/// Raises the calling thread to SCHED_FIFO for its lifetime (when allowed) and restores it.
class RealtimeScope {
 public:
  explicit RealtimeScope(bool wanted) {
    if (!wanted || pthread_getschedparam(pthread_self(), &policy_, &param_) != 0) return;
    sched_param rt{};
    rt.sched_priority = std::max(1, sched_get_priority_max(SCHED_FIFO) / 2);
    active_ = pthread_setschedparam(pthread_self(), SCHED_FIFO, &rt) == 0;
  }
  ~RealtimeScope() {
    if (active_) pthread_setschedparam(pthread_self(), policy_, &param_);
  }
  bool active() const { return active_; }

 private:
  int policy_ = SCHED_OTHER;
  sched_param param_{};
  bool active_ = false;
};

}  // namespace

HapticLoopResult run_haptic_loop(HapticProbe& probe, const ProbeTrajectory& trajectory, const HapticLoopOptions& o) {
  require(o.rate_hz > 0 && std::isfinite(o.rate_hz), "the force rate must be positive", "rate_hz");
  const double seconds = o.seconds > 0 ? o.seconds : trajectory.end_s();
  require(seconds > 0, "nothing to run: the trajectory ends at t = 0 and no duration is given", "seconds",
          "give the run's length in seconds, or a trajectory that lasts");
  using clock = std::chrono::steady_clock;
  const auto period = std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(1 / o.rate_hz));

  HapticLoopResult r;
  r.samples.reserve(std::size_t(seconds * o.rate_hz * 1.05) + 16);
  probe.set_probe_position(trajectory.at(0));
  const HapticUpdate before = probe.last_update();
  probe.start();  // before the priority rises: the update thread keeps the normal policy
  const RealtimeScope realtime(o.realtime);
  r.realtime = realtime.active();
  const auto start = clock::now();
  auto deadline = start;
  std::vector<double> intervals;
  intervals.reserve(r.samples.capacity());
  for (;;) {
    std::this_thread::sleep_until(deadline);
    const auto now = clock::now();
    const double t = std::chrono::duration<double>(now - start).count();
    if (t >= seconds) break;
    const Vec3 x = trajectory.at(t);
    probe.set_probe_position(x);
    const HapticUpdate u = probe.last_update();
    if (u.blown_up) {
      r.blown_up = true;
      r.message = u.message;
      break;
    }
    if (u.folded() && r.first_fold_time_s < 0) r.first_fold_time_s = t;
    if (!r.samples.empty()) intervals.push_back(t - r.samples.back().time_s);
    r.samples.push_back({t, x, probe.force(), u.count, u.min_det_f});
    // The next deadline is one period on; after a stall longer than a period, restart from now
    // instead of firing a burst of late outputs.
    deadline += period;
    if (deadline + period < clock::now()) deadline = clock::now();
  }
  probe.stop();
  r.wall_s = std::chrono::duration<double>(clock::now() - start).count();
  // A last fold check of the final state (the thread's last one may be up to a check interval old).
  if (!probe.last_update().blown_up) probe.check_fold();
  const HapticUpdate after = probe.last_update();
  if (after.blown_up && !r.blown_up) r.blown_up = true, r.message = after.message;
  r.intervals = interval_stats(intervals, 1 / o.rate_hz);
  if (r.samples.size() > 1)
    r.achieved_rate_hz = double(r.samples.size() - 1) / (r.samples.back().time_s - r.samples.front().time_s);
  r.updates = after.count - before.count;
  r.steps = after.steps - before.steps;
  r.update_rate_hz = r.wall_s > 0 ? double(r.updates) / r.wall_s : 0;
  r.folded = after.folded_checks > before.folded_checks;
  r.min_det_f = after.lowest_det_f;
  r.fold_checks = after.fold_checks - before.fold_checks;
  r.folded_checks = after.folded_checks - before.folded_checks;
  r.fold_check_wall_s = after.fold_check_wall_s - before.fold_check_wall_s;
  if (r.folded) {
    r.first_fold_update = after.first_fold_update;
    if (r.first_fold_time_s < 0) r.first_fold_time_s = r.wall_s;  // seen only by the last check
  }
  return r;
}

}  // namespace vb
