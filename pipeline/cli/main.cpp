// camhead: the command line. Each subcommand lives in its own file and
// registers itself here.
#include <csignal>
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "cli/commands.h"

int main(int argc, char **argv) {
  // A write past a file-size limit (ulimit -f) fails with EFBIG, which the
  // writers report and recover from (docs/input-errors.md), rather than
  // ending the process with SIGXFSZ halfway through a file.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"camhead: physically-based depth of field for AR camera rigs.\n"
               "Renders virtual objects with the depth of field of the physical lens and\n"
               "composites them into the camera image in one ray-tracing pass."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "camhead 0.1.0");
  camhead::cli::add_run_command(app);
  camhead::cli::add_web_command(app);
  camhead::cli::add_render_command(app);
  camhead::cli::add_devices_command(app);
  camhead::cli::add_bench_command(app);
  camhead::cli::add_calibrate_command(app);
  camhead::cli::add_lens_command(app);
  camhead::cli::add_markers_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError &e) {
    // --help and --version are ParseErrors that exit 0; every other is a
    // wrong command line, an input error like any other (exit 2), not
    // CLI11's own codes 101-127.
    return app.exit(e) == 0 ? 0 : 2;
  }
  return camhead::cli::exit_code();
}
