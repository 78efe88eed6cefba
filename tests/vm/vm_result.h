// How a hardware-lab check program reports: one `RESULT <name>: PASS|FAIL
// <detail>` line per verdict on stdout, the guest's console, which run_lab.sh
// collects on the host (a result never printed counts as failed there).
#pragma once

#include <cstdio>
#include <string>

namespace camhead::vm {

// Prints the line at once: the guest may be killed by its check timeout.
inline void print_result(const std::string &name, bool pass, const std::string &detail) {
  std::printf("RESULT %s: %s %s\n", name.c_str(), pass ? "PASS" : "FAIL", detail.c_str());
  std::fflush(stdout);
}

} // namespace camhead::vm
