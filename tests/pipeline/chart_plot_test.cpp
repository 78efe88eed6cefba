// The chart's drawing and CSV (pipeline/chart/chart_plot.h): every label the chart
// writes has glyphs, series land in their colours, CSV fields are quoted.
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include "chart/chart_plot.h"

#include <gtest/gtest.h>

namespace camhead::cli::chart {
namespace {

TEST(ChartPlot, FontCoversTheChartsText) {
  for (const std::string s :
       {"frame time (ms)", "relative RMSE", "pinhole+gather", "uniform", "1e-05", "0.001",
        "depth edges (12% of pixels, 8 px)", "ar_basic 720x576, NVIDIA H100: labels/rpp",
        "Moving rig: registration by the board's blur", "no points"})
    for (char c : s)
      EXPECT_TRUE(font_has(c)) << "'" << c << "' in " << s;
}

TEST(ChartPlot, DrawsSeriesAxesAndLegend) {
  Panel panel;
  panel.title = "all pixels";
  panel.x_label = "frame time (ms)";
  panel.y_label = "relative RMSE";
  const Rgb red{214, 39, 40}, blue{31, 119, 180};
  panel.series.push_back({"a", red, Marker::square, {1.0, 10.0, 100.0}, {0.1, 0.03, 0.01}, {}});
  panel.series.push_back({"b", blue, Marker::circle, {2.0, 0.0}, {0.2, 0.1}, {"1", "2"}});
  const std::vector<Panel> panels = {panel, panel};
  const Canvas canvas = plot_log_log("title", panels, 320, 240);
  EXPECT_EQ(canvas.width, 640);
  EXPECT_GT(canvas.height, 240);
  ASSERT_EQ(canvas.rgb.size(), std::size_t(canvas.width) * canvas.height * 3);
  int reds = 0, blues = 0, blacks = 0;
  for (int y = 0; y < canvas.height; ++y)
    for (int x = 0; x < canvas.width; ++x) {
      const Rgb p = canvas.pixel(x, y);
      reds += p == red;
      blues += p == blue;
      blacks += p == Rgb{0, 0, 0};
    }
  EXPECT_GT(reds, 200);    // lines and markers in both panels
  EXPECT_GT(blues, 40);    // one valid point (x = 0 has no log) and its legend entry
  EXPECT_GT(blacks, 2000); // axes, ticks, text
}

// The legend goes where it hides no point: a series that rises into the
// top-right corner shows as much of itself as its mirror image, which falls
// away from it (the legend there would hide the last marker and segment).
TEST(ChartPlot, TheLegendHidesNoPoint) {
  const Rgb red{214, 39, 40};
  const auto reds = [&](std::vector<double> ys) {
    Panel panel;
    panel.series.push_back(
        {"rises", red, Marker::square, {1.5, 4.0, 12.0, 30.0, 70.0}, std::move(ys), {}});
    const Canvas canvas = plot_log_log("", std::vector<Panel>{panel}, 480, 360);
    int n = 0;
    for (int y = 0; y < canvas.height; ++y)
      for (int x = 0; x < canvas.width; ++x)
        n += canvas.pixel(x, y) == red;
    return n;
  };
  // On axes of 1 .. 100 and 0.01 .. 1: y and 0.01 / y mirror each other.
  const std::vector<double> up = {0.012, 0.04, 0.12, 0.35, 0.85};
  std::vector<double> down;
  for (const double y : up)
    down.push_back(0.01 / y);
  const int rising = reds(up);
  const int falling = reds(down);
  EXPECT_GT(rising, 200);
  EXPECT_NEAR(rising, falling, 8);
}

// A panel whose series have no point that a log axis can show (none, or
// only zeros and NaN) says so in the middle of its plot, with no legend
// for lines that are not there.
TEST(ChartPlot, AnEmptyPanelSaysSo) {
  const Rgb red{214, 39, 40};
  Panel empty;
  empty.title = "pose held or predicted";
  empty.series.push_back({"worst", red, Marker::triangle, {0.0, 5.0}, {0.3, 0.0}, {}});
  const Canvas canvas = plot_log_log("", std::vector<Panel>{empty}, 320, 240);
  int reds = 0, middle_blacks = 0;
  for (int y = 0; y < canvas.height; ++y)
    for (int x = 0; x < canvas.width; ++x) {
      const Rgb p = canvas.pixel(x, y);
      reds += p == red;
      const bool middle =
          std::abs(x - canvas.width / 2) < 60 && std::abs(y - canvas.height / 2) < 20;
      middle_blacks += middle && p == Rgb{0, 0, 0};
    }
  EXPECT_EQ(reds, 0) << "no line, marker or legend entry";
  EXPECT_GT(middle_blacks, 50) << "the words in the middle";
}

TEST(ChartPlot, CsvQuotesWhereNeeded) {
  const std::vector<std::string> fields = {"plain", "a,b", "say \"hi\"", ""};
  EXPECT_EQ(csv_row(fields), "plain,\"a,b\",\"say \"\"hi\"\"\",");
}

} // namespace
} // namespace camhead::cli::chart
