#include "chart/chart_plot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

namespace camhead::cli::chart {

namespace {

// ---------------------------------------------------------------- font

// 5x7 glyphs: seven rows top to bottom, bit 4 the leftmost dot.
struct Glyph {
  char c;
  std::array<std::uint8_t, 7> rows;
};

constexpr Glyph kFont[] = {
    {'0', {0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e}},
    {'1', {0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e}},
    {'2', {0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f}},
    {'3', {0x1e, 0x01, 0x01, 0x0e, 0x01, 0x01, 0x1e}},
    {'4', {0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02}},
    {'5', {0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e}},
    {'6', {0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e}},
    {'7', {0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e}},
    {'9', {0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c}},
    {'A', {0x0e, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11}},
    {'B', {0x1e, 0x11, 0x11, 0x1e, 0x11, 0x11, 0x1e}},
    {'C', {0x0e, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0e}},
    {'D', {0x1c, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1c}},
    {'E', {0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x1f}},
    {'F', {0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x10}},
    {'G', {0x0e, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0f}},
    {'H', {0x11, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11}},
    {'I', {0x0e, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e}},
    {'J', {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0c}},
    {'K', {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}},
    {'L', {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1f}},
    {'M', {0x11, 0x1b, 0x15, 0x15, 0x11, 0x11, 0x11}},
    {'N', {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}},
    {'O', {0x0e, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e}},
    {'P', {0x1e, 0x11, 0x11, 0x1e, 0x10, 0x10, 0x10}},
    {'Q', {0x0e, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0d}},
    {'R', {0x1e, 0x11, 0x11, 0x1e, 0x14, 0x12, 0x11}},
    {'S', {0x0f, 0x10, 0x10, 0x0e, 0x01, 0x01, 0x1e}},
    {'T', {0x1f, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'U', {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e}},
    {'V', {0x11, 0x11, 0x11, 0x11, 0x11, 0x0a, 0x04}},
    {'W', {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0a}},
    {'X', {0x11, 0x11, 0x0a, 0x04, 0x0a, 0x11, 0x11}},
    {'Y', {0x11, 0x11, 0x0a, 0x04, 0x04, 0x04, 0x04}},
    {'Z', {0x1f, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1f}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x0c}},
    {',', {0x00, 0x00, 0x00, 0x00, 0x0c, 0x04, 0x08}},
    {'-', {0x00, 0x00, 0x00, 0x1f, 0x00, 0x00, 0x00}},
    {'+', {0x00, 0x04, 0x04, 0x1f, 0x04, 0x04, 0x00}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}},
    {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {'/', {0x01, 0x02, 0x02, 0x04, 0x08, 0x08, 0x10}},
    {':', {0x00, 0x0c, 0x0c, 0x00, 0x0c, 0x0c, 0x00}},
    {'=', {0x00, 0x00, 0x1f, 0x00, 0x1f, 0x00, 0x00}},
    {'%', {0x19, 0x19, 0x02, 0x04, 0x08, 0x13, 0x13}},
    {'_', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1f}},
    {'*', {0x00, 0x04, 0x15, 0x0e, 0x15, 0x04, 0x00}},
    {'\'', {0x04, 0x04, 0x08, 0x00, 0x00, 0x00, 0x00}},
};

const Glyph *find_glyph(char c) {
  if (c >= 'a' && c <= 'z')
    c = char(c - 'a' + 'A');
  for (const Glyph &g : kFont)
    if (g.c == c)
      return &g;
  return nullptr;
}

// ---------------------------------------------------------------- axes

struct LogAxis {
  int lo = 0; // decades: 10^lo .. 10^hi
  int hi = 1;
  double pixel_from = 0.0, pixel_to = 1.0; // screen position of 10^lo, 10^hi

  [[nodiscard]] double map(double v) const {
    const double t = (std::log10(v) - lo) / double(hi - lo);
    return pixel_from + t * (pixel_to - pixel_from);
  }
};

LogAxis axis_spanning(double min_v, double max_v) {
  LogAxis axis;
  // No data leaves min_v at infinity and max_v at 0.
  if (!(min_v > 0.0) || !std::isfinite(min_v) || !(max_v > 0.0) || !std::isfinite(max_v)) {
    return axis; // no data: one decade, 1..10
  }
  axis.lo = int(std::floor(std::log10(min_v) + 1e-9));
  axis.hi = int(std::ceil(std::log10(max_v) - 1e-9));
  if (axis.hi <= axis.lo)
    axis.hi = axis.lo + 1;
  return axis;
}

std::string tick_label(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// Whether a point has a place on log axes: positive and finite both ways.
bool on_log_axes(double x, double y) {
  return x > 0.0 && y > 0.0 && std::isfinite(x) && std::isfinite(y);
}

void draw_marker(Canvas &canvas, int cx, int cy, Marker marker, Rgb color) {
  constexpr int r = 4;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      bool inside = false;
      switch (marker) {
      case Marker::circle:
        inside = dx * dx + dy * dy <= r * r;
        break;
      case Marker::square:
        inside = std::abs(dx) <= r - 1 && std::abs(dy) <= r - 1;
        break;
      case Marker::diamond:
        inside = std::abs(dx) + std::abs(dy) <= r;
        break;
      case Marker::triangle:
        inside = dy >= -r + 1 && 2 * std::abs(dx) <= dy + r;
        break;
      }
      if (inside)
        canvas.set(cx + dx, cy + dy, color);
    }
}

const Rgb kBlack{0, 0, 0};
const Rgb kGridMajor{200, 200, 200};
const Rgb kGridMinor{232, 232, 232};
const Rgb kWhite{255, 255, 255};

void draw_panel(Canvas &canvas, const Panel &panel, int left, int top, int width, int height) {
  // Plot area inside the panel's margins.
  const int x0 = left + 78, x1 = left + width - 16;
  const int y0 = top + 30, y1 = top + height - 50;

  double min_x = std::numeric_limits<double>::infinity(), max_x = 0.0;
  double min_y = min_x, max_y = 0.0;
  for (const Series &s : panel.series)
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!on_log_axes(s.x[i], s.y[i]))
        continue;
      min_x = std::min(min_x, s.x[i]);
      max_x = std::max(max_x, s.x[i]);
      min_y = std::min(min_y, s.y[i]);
      max_y = std::max(max_y, s.y[i]);
    }
  LogAxis ax = axis_spanning(min_x, max_x);
  LogAxis ay = axis_spanning(min_y, max_y);
  ax.pixel_from = x0;
  ax.pixel_to = x1;
  ay.pixel_from = y1;
  ay.pixel_to = y0;

  canvas.text(left + (width - text_width(panel.title, 2)) / 2, top + 6, panel.title, kBlack, 2);

  // Grid and ticks: every 1..9 x 10^k; labels at decades, and at 2 and 5
  // when the axis spans at most two decades.
  const auto ticks = [](const LogAxis &a, auto &&draw) {
    for (int k = a.lo; k <= a.hi; ++k)
      for (int m = 1; m <= 9; ++m) {
        if (k == a.hi && m > 1)
          break;
        const double v = m * std::pow(10.0, k);
        const bool labelled = m == 1 || (a.hi - a.lo <= 2 && (m == 2 || m == 5));
        draw(v, m == 1, labelled);
      }
  };
  ticks(ax, [&](double v, bool major, bool labelled) {
    const int px = int(std::lround(ax.map(v)));
    canvas.line(px, y0, px, y1, major ? kGridMajor : kGridMinor);
    canvas.line(px, y1, px, y1 + (major ? 6 : 3), kBlack);
    if (labelled) {
      const std::string label = tick_label(v);
      canvas.text(px - text_width(label) / 2, y1 + 9, label, kBlack);
    }
  });
  ticks(ay, [&](double v, bool major, bool labelled) {
    const int py = int(std::lround(ay.map(v)));
    canvas.line(x0, py, x1, py, major ? kGridMajor : kGridMinor);
    canvas.line(x0 - (major ? 6 : 3), py, x0, py, kBlack);
    if (labelled) {
      const std::string label = tick_label(v);
      canvas.text(x0 - 9 - text_width(label), py - 3, label, kBlack);
    }
  });
  canvas.line(x0, y0, x0, y1, kBlack);
  canvas.line(x0, y1, x1, y1, kBlack);
  canvas.line(x1, y0, x1, y1, kBlack);
  canvas.line(x0, y0, x1, y0, kBlack);
  canvas.text((x0 + x1 - text_width(panel.x_label, 2)) / 2, y1 + 24, panel.x_label, kBlack, 2);
  canvas.text(left + 6, (y0 + y1 + text_width(panel.y_label, 2)) / 2, panel.y_label, kBlack, 2,
              true);

  // A panel with nothing to plot (a run with no frame of that kind) says
  // so, where an empty grid and a legend would suggest points missing.
  if (!(max_x > 0.0)) {
    const std::string none = "no points";
    canvas.text((x0 + x1 - text_width(none, 2)) / 2, (y0 + y1) / 2 - 7, none, kBlack, 2);
    return;
  }

  // Series: lines between consecutive valid points, then markers on top.
  for (const Series &s : panel.series) {
    bool have_previous = false;
    double px_prev = 0.0, py_prev = 0.0;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!on_log_axes(s.x[i], s.y[i]))
        continue;
      const double px = ax.map(s.x[i]), py = ay.map(s.y[i]);
      if (have_previous)
        canvas.line(px_prev, py_prev, px, py, s.color, 2);
      px_prev = px;
      py_prev = py;
      have_previous = true;
    }
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!on_log_axes(s.x[i], s.y[i]))
        continue;
      const int px = int(std::lround(ax.map(s.x[i]))), py = int(std::lround(ay.map(s.y[i])));
      draw_marker(canvas, px, py, s.marker, s.color);
      if (i < s.labels.size())
        canvas.text(px + 6, py - 11, s.labels[i], s.color);
    }
  }

  // The legend in the corner where it hides the fewest points: the top
  // right, unless the series reach it (a wide legend over a falling error
  // hides its first frames; a rising series ends there).
  int legend_w = 0;
  for (const Series &s : panel.series)
    legend_w = std::max(legend_w, text_width(s.name, 2));
  legend_w += 50;
  const int row_h = 20;
  const int legend_h = int(panel.series.size()) * row_h + 8;
  const auto hidden = [&](int lx, int ly) {
    int points = 0;
    for (const Series &s : panel.series)
      for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
        if (!on_log_axes(s.x[i], s.y[i]))
          continue;
        const double px = ax.map(s.x[i]), py = ay.map(s.y[i]);
        points += px >= lx - 5 && px <= lx + legend_w + 5 && py >= ly - 5 &&
                  py <= ly + legend_h + 5; // a marker's reach
      }
    return points;
  };
  int lx = x1 - legend_w - 8, ly = y0 + 8;
  int least = hidden(lx, ly);
  for (const auto &[cx, cy] : {std::pair{x0 + 8, y1 - legend_h - 8}, std::pair{x0 + 8, y0 + 8},
                               std::pair{x1 - legend_w - 8, y1 - legend_h - 8}}) {
    const int points = hidden(cx, cy);
    if (points < least) {
      least = points;
      lx = cx;
      ly = cy;
    }
  }
  canvas.fill_rect(lx, ly, lx + legend_w, ly + legend_h, kWhite);
  canvas.line(lx, ly, lx + legend_w, ly, kBlack);
  canvas.line(lx, ly + legend_h, lx + legend_w, ly + legend_h, kBlack);
  canvas.line(lx, ly, lx, ly + legend_h, kBlack);
  canvas.line(lx + legend_w, ly, lx + legend_w, ly + legend_h, kBlack);
  for (std::size_t i = 0; i < panel.series.size(); ++i) {
    const Series &s = panel.series[i];
    const int cy = ly + 4 + int(i) * row_h + row_h / 2;
    canvas.line(lx + 6, cy, lx + 36, cy, s.color, 2);
    draw_marker(canvas, lx + 21, cy, s.marker, s.color);
    canvas.text(lx + 44, cy - 7, s.name, kBlack, 2);
  }
}

} // namespace

Canvas::Canvas(int w, int h, Rgb background)
    : width(w), height(h), rgb(std::size_t(w) * std::size_t(h) * 3) {
  for (std::size_t i = 0; i < rgb.size(); i += 3) {
    rgb[i] = background.r;
    rgb[i + 1] = background.g;
    rgb[i + 2] = background.b;
  }
}

Rgb Canvas::pixel(int x, int y) const {
  const std::uint8_t *p = &rgb[(std::size_t(y) * width + x) * 3];
  return {p[0], p[1], p[2]};
}

void Canvas::set(int x, int y, Rgb color) {
  if (x < 0 || y < 0 || x >= width || y >= height)
    return;
  std::uint8_t *p = &rgb[(std::size_t(y) * width + x) * 3];
  p[0] = color.r;
  p[1] = color.g;
  p[2] = color.b;
}

void Canvas::fill_rect(int x0, int y0, int x1, int y1, Rgb color) {
  for (int y = std::min(y0, y1); y <= std::max(y0, y1); ++y)
    for (int x = std::min(x0, x1); x <= std::max(x0, x1); ++x)
      set(x, y, color);
}

void Canvas::line(double x0, double y0, double x1, double y1, Rgb color, int thickness) {
  const double steps = std::max({std::abs(x1 - x0), std::abs(y1 - y0), 1.0});
  const int lo = -(thickness - 1) / 2, hi = thickness / 2;
  for (int i = 0; i <= int(std::ceil(steps)); ++i) {
    const double t = std::min(1.0, i / steps);
    const int x = int(std::lround(x0 + t * (x1 - x0)));
    const int y = int(std::lround(y0 + t * (y1 - y0)));
    for (int dy = lo; dy <= hi; ++dy)
      for (int dx = lo; dx <= hi; ++dx)
        set(x + dx, y + dy, color);
  }
}

void Canvas::text(int x, int y, const std::string &s, Rgb color, int scale, bool vertical) {
  int pen = 0;
  for (char c : s) {
    const Glyph *g = find_glyph(c);
    if (g != nullptr) {
      for (int row = 0; row < 7; ++row)
        for (int col = 0; col < 5; ++col) {
          if ((g->rows[row] >> (4 - col) & 1) == 0)
            continue;
          // Horizontal: dot (col, row) right of the pen; vertical: the glyph
          // turned a quarter anticlockwise, reading upwards from (x, y).
          const int gx = vertical ? x + row * scale : x + (pen + col) * scale;
          const int gy = vertical ? y - (pen + col + 1) * scale + 1 : y + row * scale;
          fill_rect(gx, gy, gx + scale - 1, gy + scale - 1, color);
        }
    }
    pen += 6;
  }
}

int text_width(const std::string &s, int scale) {
  return s.empty() ? 0 : (int(s.size()) * 6 - 1) * scale;
}

bool font_has(char c) {
  return c == ' ' || find_glyph(c) != nullptr;
}

Canvas plot_log_log(const std::string &title, std::span<const Panel> panels, int panel_width,
                    int panel_height) {
  const int title_h = title.empty() ? 0 : 34;
  Canvas canvas(std::max(1, int(panels.size())) * panel_width, panel_height + title_h, kWhite);
  if (!title.empty())
    canvas.text((canvas.width - text_width(title, 2)) / 2, 10, title, kBlack, 2);
  for (std::size_t i = 0; i < panels.size(); ++i)
    draw_panel(canvas, panels[i], int(i) * panel_width, title_h, panel_width, panel_height);
  return canvas;
}

std::string csv_row(std::span<const std::string> fields) {
  std::string out;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    if (i > 0)
      out += ',';
    const std::string &f = fields[i];
    if (f.find_first_of(",\"\n\r") == std::string::npos) {
      out += f;
      continue;
    }
    out += '"';
    for (char c : f) {
      if (c == '"')
        out += '"';
      out += c;
    }
    out += '"';
  }
  return out;
}

} // namespace camhead::cli::chart
