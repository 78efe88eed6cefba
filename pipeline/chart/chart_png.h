// A chart's canvas (chart_plot.h, 8-bit sRGB) written as a PNG through the
// renderer's image writer, which takes linear light; replaced whole, as
// every writer of camhead's does.
#pragma once

#include <filesystem>

#include "chart_plot.h"

namespace camhead::cli::chart {

void write_png(const std::filesystem::path &png, const Canvas &canvas);

} // namespace camhead::cli::chart
