#pragma once
/// A one-line progress display on stderr, drawn only when stderr is a terminal.
#include <chrono>
#include <string>

namespace vb::app {

class Progress {
 public:
  explicit Progress(bool enabled);
  ~Progress();
  /// fraction in [0, 1]; text is appended after the bar. Redraws at most 10 times a second.
  void update(double fraction, const std::string& text);
  void finish();
  /// Prints `line` (with its newline) to stdout above the bar, which is drawn again on the
  /// next update.
  void print_above(const std::string& line);

 private:
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point last_{};
};

}  // namespace vb::app
