// camhead bench chart: the speed-versus-accuracy chart (chart_command.cpp).
#pragma once

#include <CLI/CLI.hpp>

namespace camhead::cli {

// Adds `chart` under the `bench` subcommand.
void add_bench_chart_command(CLI::App &bench);

} // namespace camhead::cli
