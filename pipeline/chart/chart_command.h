// camhead bench chart: the speed-versus-accuracy chart (chart_command.cpp),
// and camhead bench live: the live frame's error against time
// (cli/live_bench_command.cpp).
#pragma once

#include <CLI/CLI.hpp>

namespace camhead::cli {

// Adds `chart` under the `bench` subcommand.
void add_bench_chart_command(CLI::App &bench);
// Adds `live` under the `bench` subcommand.
void add_bench_live_command(CLI::App &bench);

} // namespace camhead::cli
