// How a hardware-lab check program reports: one `RESULT <name>: PASS|FAIL
// <detail>` line per verdict on stdout, the guest's console, which run_lab.sh
// collects on the host (a result never printed counts as failed there).
#pragma once

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace camhead::vm {

// Prints the line at once: the guest may be killed by its check timeout.
inline void print_result(const std::string &name, bool pass, const std::string &detail) {
  std::printf("RESULT %s: %s %s\n", name.c_str(), pass ? "PASS" : "FAIL", detail.c_str());
  std::fflush(stdout);
}

// "median M ms, worst W ms" of a fault loop's times (at least one), with
// `decimals` digits after the point.
inline std::string median_and_worst_ms(std::vector<double> ms, int decimals = 0) {
  std::sort(ms.begin(), ms.end());
  char text[80];
  std::snprintf(text, sizeof text, "median %.*f ms, worst %.*f ms", decimals, ms[ms.size() / 2],
                decimals, ms.back());
  return text;
}

} // namespace camhead::vm
