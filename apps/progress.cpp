#include "apps/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace vb::app {
namespace {

/// Seconds of residual history the rate of convergence is measured over.
constexpr double kRateWindowS = 5;

}  // namespace

Progress::Progress(bool enabled, double line_interval_s)
    : enabled_(enabled), terminal_(isatty(STDERR_FILENO)), line_interval_s_(line_interval_s) {}

Progress::~Progress() { finish(); }

double Progress::elapsed_s() const { return std::chrono::duration<double>(Clock::now() - phase_start_).count(); }

std::string Progress::duration_text(double seconds) {
  char text[32];
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  if (seconds < 100) std::snprintf(text, sizeof text, "%.0f s", seconds);
  else if (seconds < 6000) std::snprintf(text, sizeof text, "%.1f min", seconds / 60);
  else std::snprintf(text, sizeof text, "%.1f h", seconds / 3600);
  return text;
}

void Progress::phase(const std::string& name) {
  finish();
  phase_ = name;
  last_ = {};
  phase_start_ = Clock::now();
  have_residual_ = false;
  recent_.clear();
}

void Progress::update(double fraction, const std::string& text) {
  fraction = std::clamp(fraction, 0.0, 1.0);
  const double t = elapsed_s();
  draw(fraction, fraction > 0 ? t * (1 - fraction) / fraction : NAN, text);
}

void Progress::converge(double residual, double tolerance, const std::string& text) {
  if (!(residual > 0) || !(tolerance > 0) || !std::isfinite(residual)) return draw(0, NAN, text);
  const double log_r = std::log(residual), log_tol = std::log(tolerance), t = elapsed_s();
  if (!have_residual_ || log_r > largest_log_residual_) largest_log_residual_ = log_r;
  have_residual_ = true;
  recent_.emplace_back(t, log_r);
  while (recent_.size() > 2 && t - recent_[1].first >= kRateWindowS) recent_.pop_front();
  const double span = largest_log_residual_ - log_tol;
  const double fraction = span > 0 ? (largest_log_residual_ - log_r) / span : 1.0;
  double left = NAN;
  if (log_r <= log_tol) {
    left = 0;
  } else if (recent_.size() >= 2 && recent_.back().first > recent_.front().first) {
    const double rate = (recent_.front().second - log_r) / (recent_.back().first - recent_.front().first);
    if (rate > 0) left = (log_r - log_tol) / rate;
  }
  char head[96];
  std::snprintf(head, sizeof head, "%.2e → %.0e  ", residual, tolerance);
  draw(std::clamp(fraction, 0.0, 1.0), left, head + text);
}

void Progress::draw(double fraction, double seconds_left, const std::string& text) {
  if (!enabled_) return;
  const auto now = Clock::now();
  const std::string left = "~" + duration_text(seconds_left) + " left";
  const std::string name = phase_.empty() ? "" : phase_ + ": ";
  if (!terminal_) {
    if (now - last_line_ < std::chrono::duration<double>(line_interval_s_)) return;  // also a short run stays silent
    last_line_ = now;
    std::fprintf(stderr, "voxbreast: %s%3d%%, %s, %s elapsed; %s\n", name.c_str(), int(100 * fraction),
                 left.c_str(), duration_text(elapsed_s()).c_str(), text.c_str());
    std::fflush(stderr);
    return;
  }
  if (drawn_ && now - last_ < std::chrono::milliseconds(100)) return;
  last_ = now;
  constexpr int width = 24;
  std::string bar(std::size_t(fraction * width), '#');
  bar.resize(width, '-');
  std::fprintf(stderr, "\r%s[%s] %3d%% %s  %s\033[K", name.c_str(), bar.c_str(), int(100 * fraction), left.c_str(),
               text.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void Progress::print_above(const std::string& line) {
  if (enabled_ && terminal_ && drawn_) std::fprintf(stderr, "\r\033[K");
  std::fputs(line.c_str(), stdout);
  std::fflush(stdout);
  if (terminal_) drawn_ = false;  // redraw at once on the next update
}

void Progress::finish() {
  if (enabled_ && terminal_ && drawn_) std::fprintf(stderr, "\n");
  if (terminal_) drawn_ = false;
}

}  // namespace vb::app
