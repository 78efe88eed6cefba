// camhead: the command line. Each subcommand lives in its own file and
// registers itself here.
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "commands.h"

int main(int argc, char **argv) {
  CLI::App app{"camhead: physically-based depth of field for AR camera rigs.\n"
               "Renders virtual objects with the depth of field of the physical lens and\n"
               "composites them into the camera image in one ray-tracing pass."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "camhead 0.1.0");
  camhead::cli::add_run_command(app);
  camhead::cli::add_render_command(app);
  camhead::cli::add_devices_command(app);
  camhead::cli::add_bench_command(app);
  camhead::cli::add_calibrate_command(app);
  camhead::cli::add_lens_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError &e) {
    return app.exit(e);
  }
  return camhead::cli::exit_code();
}
