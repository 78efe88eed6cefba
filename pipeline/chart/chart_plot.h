// The speed-versus-accuracy chart as a picture and a table: log-log panels of
// error against frame time drawn into an RGB buffer with a built-in 5x7
// bitmap font, and CSV text. Plain data in, bytes out: no image library, so
// that the drawing is testable on its own (`camhead bench chart` writes the
// canvas through renderer/image_io).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace camhead::cli::chart {

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb &) const = default;
};

// 8-bit sRGB, row 0 at the top, 3 bytes per pixel.
struct Canvas {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;

  Canvas(int w, int h, Rgb background);
  [[nodiscard]] Rgb pixel(int x, int y) const;
  void set(int x, int y, Rgb color);                         // ignores points outside
  void fill_rect(int x0, int y0, int x1, int y1, Rgb color); // inclusive corners
  void line(double x0, double y0, double x1, double y1, Rgb color, int thickness = 1);
  // Text in the 5x7 font at `scale` pixels per font dot, top-left at (x, y);
  // letters are drawn as capitals. `vertical` runs bottom to top.
  void text(int x, int y, const std::string &s, Rgb color, int scale = 1, bool vertical = false);
};

// Width in pixels of `s` drawn at `scale` (6 dots per character).
[[nodiscard]] int text_width(const std::string &s, int scale = 1);
// True when the font has a glyph for c (after mapping lower case to capitals).
[[nodiscard]] bool font_has(char c);

enum class Marker { circle, square, diamond, triangle };

struct Series {
  std::string name;
  Rgb color;
  Marker marker = Marker::circle;
  std::vector<double> x, y;        // points; those not > 0 (no log) are skipped
  std::vector<std::string> labels; // optional, drawn beside each point (e.g. rpp)
};

struct Panel {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<Series> series;
};

// Panels side by side, each with log-log axes spanning its data (whole
// decades), grid, tick labels, axis labels and a legend; `title` on top.
[[nodiscard]] Canvas plot_log_log(const std::string &title, std::span<const Panel> panels,
                                  int panel_width = 640, int panel_height = 480);

// One CSV record (RFC 4180 quoting where a field needs it), without newline.
[[nodiscard]] std::string csv_row(std::span<const std::string> fields);

} // namespace camhead::cli::chart
