// A one-line progress display for long renders on standard error.
#pragma once

#include <chrono>
#include <string>

namespace camhead::base {

class ProgressLine {
public:
  // `unit` names what update() counts ("rpp": the samples of a render).
  explicit ProgressLine(std::string label, std::string unit = "rpp");
  // Redraws on a terminal (at most ten times a second); elsewhere, such as in
  // a service log, prints a line at every tenth of the work.
  void update(int done, int total);
  void finish();

private:
  std::string label_;
  std::string unit_;
  bool terminal_;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

} // namespace camhead::base
