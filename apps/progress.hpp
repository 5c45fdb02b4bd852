#pragma once
/// Progress on stderr. On a terminal: a one-line bar redrawn at most 10 times a second. Without a
/// terminal (batch logs): a one-line status at most every `line_interval_s` seconds, so that a
/// log shows life. Disabled (--quiet): nothing.
///
/// Two measures of progress: a fraction of known work done (image slices, runs of a series), or
/// convergence, a residual falling towards its tolerance. For convergence the bar is the
/// residual's fall on a log scale, from the largest residual of the phase to the tolerance, and
/// the time left is the log-distance still to go over the rate it fell in the last few seconds.
#include <chrono>
#include <deque>
#include <string>
#include <utility>

namespace vb::app {

class Progress {
 public:
  /// line_interval_s: seconds between status lines when stderr is not a terminal (> 0).
  explicit Progress(bool enabled, double line_interval_s = 10);
  ~Progress();
  /// Starts a phase (e.g. "solve", "image outputs"): its name heads the line; the estimate of
  /// the time left starts afresh.
  void phase(const std::string& name);
  /// fraction of the phase done in [0, 1]; text is appended after the bar.
  void update(double fraction, const std::string& text);
  /// A falling measure (a residual) against its tolerance (both > 0), shown as "R → TOL"; text
  /// is appended after it.
  void converge(double residual, double tolerance, const std::string& text);
  void finish();
  /// Prints `line` (with its newline) to stdout above the bar, which is drawn again on the
  /// next update.
  void print_above(const std::string& line);

  /// "12 s", "3.4 min", or "?" for a negative or non-finite number of seconds.
  static std::string duration_text(double seconds);

 private:
  using Clock = std::chrono::steady_clock;
  void draw(double fraction, double seconds_left, const std::string& text);
  double elapsed_s() const;

  bool enabled_, terminal_;
  double line_interval_s_;
  bool drawn_ = false;
  std::string phase_;
  Clock::time_point phase_start_ = Clock::now(), last_ = {}, last_line_ = Clock::now();
  double largest_log_residual_ = 0;
  bool have_residual_ = false;
  std::deque<std::pair<double, double>> recent_;  ///< (seconds into the phase, log residual)
};

}  // namespace vb::app
