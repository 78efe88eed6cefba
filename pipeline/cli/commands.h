// Subcommands of the camhead command line.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <CLI/CLI.hpp>

#include "camhead/base/path_text.h"

namespace camhead::cli {

void add_render_command(CLI::App &app);    // camhead render
void add_devices_command(CLI::App &app);   // camhead devices
void add_bench_command(CLI::App &app);     // camhead bench
void add_calibrate_command(CLI::App &app); // camhead calibrate
void add_lens_command(CLI::App &app);      // camhead lens monitor | record
void add_markers_command(CLI::App &app);   // camhead markers draw
void add_run_command(CLI::App &app);       // camhead run
void add_web_command(CLI::App &app);       // camhead web-password

// A command-line path held to the rule every path camhead takes from a user
// follows (base/path_text.h): no control characters.
[[nodiscard]] inline CLI::Validator path_text() {
  return CLI::Validator([](std::string &text) { return base::path_text_problem(text); }, "PATH");
}

// A number within [lo, hi]; CLI::Range lets NaN through (it compares false
// with every bound), and `--duration nan` would run forever.
[[nodiscard]] inline CLI::Validator finite_within(double lo, double hi) {
  return CLI::Validator(
      [=](std::string &text) -> std::string {
        char *end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0' || !std::isfinite(value) || value < lo ||
            value > hi) {
          char range[64];
          std::snprintf(range, sizeof range, " is not a number within %g .. %g", lo, hi);
          return text + range;
        }
        return {};
      },
      "FINITE");
}

// The exit status the chosen subcommand left (0 = success).
[[nodiscard]] int exit_code();
void set_exit_code(int code);

} // namespace camhead::cli
