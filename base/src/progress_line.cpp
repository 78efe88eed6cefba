#include "camhead/base/progress_line.h"

#include <cstdio>

#include <unistd.h>

namespace camhead::base {

ProgressLine::ProgressLine(std::string label, std::string unit)
    : label_(std::move(label)), unit_(std::move(unit)), terminal_(isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()) {}

void ProgressLine::update(int done, int total) {
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double fraction = total > 0 ? double(done) / total : 1.0;
  if (terminal_) {
    if (done < total && now - last_draw_ < std::chrono::milliseconds(100)) {
      return;
    }
    last_draw_ = now;
    constexpr int width = 30;
    const int filled = int(fraction * width + 0.5);
    const double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
    std::fprintf(stderr, "\r%s [%-*s] %3d%%  %d/%d %s  %.1f s, about %.0f s left ", label_.c_str(),
                 width, std::string(filled, '#').c_str(), int(fraction * 100), done, total,
                 unit_.c_str(), elapsed, eta);
    std::fflush(stderr);
    return;
  }
  const int decile = int(fraction * 10.0);
  if (decile > last_decile_) {
    last_decile_ = decile;
    std::fprintf(stderr, "%s: %d/%d %s (%d%%), %.1f s\n", label_.c_str(), done, total,
                 unit_.c_str(), int(fraction * 100), elapsed);
  }
}

void ProgressLine::finish() {
  if (terminal_) {
    std::fprintf(stderr, "\n");
  }
}

} // namespace camhead::base
