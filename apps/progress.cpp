#include "apps/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace vb::app {

Progress::Progress(bool enabled) : enabled_(enabled && isatty(STDERR_FILENO)) {}

Progress::~Progress() { finish(); }

void Progress::update(double fraction, const std::string& text) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (drawn_ && now - last_ < std::chrono::milliseconds(100)) return;
  last_ = now;
  constexpr int width = 30;
  const int filled = int(std::clamp(fraction, 0.0, 1.0) * width);
  std::string bar(filled, '#');
  bar.resize(width, '-');
  std::fprintf(stderr, "\r[%s] %3d%% %s\033[K", bar.c_str(), int(100 * std::clamp(fraction, 0.0, 1.0)), text.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void Progress::print_above(const std::string& line) {
  if (enabled_ && drawn_) std::fprintf(stderr, "\r\033[K");
  std::fputs(line.c_str(), stdout);
  std::fflush(stdout);
  drawn_ = false;  // redraw at once on the next update
}

void Progress::finish() {
  if (enabled_ && drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace vb::app
