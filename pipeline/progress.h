// A one-line progress display for long renders on standard error.
#pragma once

#include <chrono>
#include <string>

namespace camhead::cli {

class ProgressLine {
public:
  explicit ProgressLine(std::string label);
  // Redraws on a terminal (at most ten times a second); elsewhere, such as in
  // a service log, prints a line at every tenth of the work.
  void update(int done, int total);
  void finish();

private:
  std::string label_;
  bool terminal_;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

} // namespace camhead::cli
