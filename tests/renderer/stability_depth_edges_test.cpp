// Stability at depth discontinuities (issue 4): a blurred foreground edge
// in front of a sharp background edge, virtual in front of real and real in
// front of virtual. Every layer is held to its thin-lens expectation: at
// image position p the foreground covers the fraction A(p) of the aperture
// (a chord of the disk the aperture projects to at the foreground's depth,
// stability_support.h edge_coverage), the remaining 1 - A(p) sees past it to
// the sharp background, and the pixel averages that over its box.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include "stability_support.h"
#include "test_scenes.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

using renderer::Image;
using renderer::RenderResult;
using renderer::Scene;

constexpr int kWidth = 128;
constexpr int kHeight = 8;
constexpr float kFNumber = 1.4f;
constexpr float kFocusM = 2.0f;      // the background is in focus
constexpr float kForegroundM = 0.4f; // 12.7 px blur circle at f/1.4
constexpr float kCameraGain = 1.1f;  // plate = 1.1 x the real proxy, as make_plate.py
// The sharp background edge lies inside the foreground's blurred rim, 2.5 px
// right of the foreground edge's projection (so one pixel is split by it).
constexpr double kBackgroundEdgeOffsetPx = 2.5;
// Largest error of a column (8 rows x 256 rays, stratified) against the
// expectation: about 3 x what the CPU reference shows.
constexpr double kCpuTolerance = 0.015;

// The analytic expectation of each layer, per column.
struct Expected {
  std::vector<double> mask, mixed, real, depth, composite, physical;
};

// The measured layers, averaged over the rows.
struct Measured {
  std::vector<double> mask, mixed, real, depth, composite;
};

Measured measure(const RenderResult &r) {
  return {test::row_average(r.mask), test::row_average(r.mixed), test::row_average(r.real),
          test::row_average(r.depth), test::row_average(r.composite)};
}

double max_abs_diff(const std::vector<double> &a, const std::vector<double> &b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    worst = std::max(worst, std::abs(a[i] - b[i]));
  }
  return worst;
}

// Largest column error of each measured layer against its expectation, and
// of the expected composite (equation 4) against the physical camera.
struct Errors {
  double mask, mixed, real, depth, composite, method;
};

Errors errors(const Measured &m, const Expected &e) {
  return {max_abs_diff(m.mask, e.mask),           max_abs_diff(m.mixed, e.mixed),
          max_abs_diff(m.real, e.real),           max_abs_diff(m.depth, e.depth),
          max_abs_diff(m.composite, e.composite), max_abs_diff(e.composite, e.physical)};
}

// The plate: the camera image, kCameraGain times the analytic real layer.
Image plate_from(const std::vector<double> &real) {
  Image plate(kWidth, kHeight, 3);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      for (int c = 0; c < 3; ++c) {
        plate.at(x, y)[c] = float(kCameraGain * real[x]);
      }
    }
  }
  return plate;
}

// Equation (4) of method.md on the analytic layers.
void fill_composite(Expected &e) {
  for (std::size_t i = 0; i < e.mask.size(); ++i) {
    const double m = e.mask[i];
    const double camera = kCameraGain * e.real[i];
    e.composite.push_back(m * e.mixed[i] + (1.0 - m) * (camera + e.mixed[i] - e.real[i]));
  }
}

void print_profile(const char *title, const Expected &e, const Measured &m, double u0) {
  std::printf("%s (column: mask expected/measured, I_m expected/measured, I_r expected/measured)\n",
              title);
  for (int i = int(u0) - 9; i <= int(u0) + 9; ++i) {
    std::printf("  col %3d: M %.4f/%.4f  I_m %.4f/%.4f  I_r %.4f/%.4f\n", i, e.mask[i], m.mask[i],
                e.mixed[i], m.mixed[i], e.real[i], m.real[i]);
  }
}

// ---------------------------------------------------------------- virtual in front of real

constexpr float kVirtualRadiance = 0.6f;
constexpr float kBackgroundDark = 0.2f;
constexpr float kBackgroundBright = 1.0f;

// A virtual half-plane (x < 0) at 0.4 m, blurred, in front of a real
// background at the focus depth that steps from 0.2 to 1.0 just right of it.
struct VirtualForeground {
  Scene scene;
  double u0 = 0.0;   // column of the foreground edge's projection
  double edge = 0.0; // column of the background edge
  double rho = 0.0;  // foreground blur radius, px
};

VirtualForeground virtual_foreground_scene() {
  VirtualForeground v;
  v.scene = test::empty_scene("virtual_foreground", kFNumber, kFocusM, kWidth, kHeight);
  const int dark = stability::add_emitter(v.scene, "background_dark", kBackgroundDark);
  const int bright = stability::add_emitter(v.scene, "background_bright", kBackgroundBright);
  const int paint = stability::add_emitter(v.scene, "virtual", kVirtualRadiance);
  v.u0 = 0.5 * kWidth;
  v.edge = v.u0 + kBackgroundEdgeOffsetPx;
  const float x_edge = float(kBackgroundEdgeOffsetPx * kFocusM / stability::focal_px(v.scene));
  stability::add_half_plane(v.scene, "real_left", kFocusM, x_edge, -1, dark, true);
  stability::add_half_plane(v.scene, "real_right", kFocusM, x_edge, +1, bright, true);
  stability::add_half_plane(v.scene, "virtual_occluder", kForegroundM, 0.0f, -1, paint, false);
  v.rho = stability::blur_radius_px(v.scene, kForegroundM);
  return v;
}

Expected expected_virtual_foreground(const VirtualForeground &v) {
  const auto coverage = [&](double p) { return stability::edge_coverage(p, v.u0, v.rho); };
  const auto background = [&](double p) {
    return p < v.edge ? kBackgroundDark : kBackgroundBright;
  };
  Expected e;
  for (int i = 0; i < kWidth; ++i) {
    e.mask.push_back(stability::pixel_average(i, coverage));
    e.mixed.push_back(stability::pixel_average(i, [&](double p) {
      return coverage(p) * kVirtualRadiance + (1.0 - coverage(p)) * background(p);
    }));
    e.real.push_back(stability::pixel_average(i, background));
    e.depth.push_back(stability::pixel_average(
        i, [&](double p) { return coverage(p) * kForegroundM + (1.0 - coverage(p)) * kFocusM; }));
    // What a camera would record if the virtual plane were real.
    e.physical.push_back(stability::pixel_average(i, [&](double p) {
      return coverage(p) * kVirtualRadiance + (1.0 - coverage(p)) * kCameraGain * background(p);
    }));
  }
  fill_composite(e);
  return e;
}

void check_virtual_foreground(const RenderResult &r, const VirtualForeground &v, double tolerance,
                              bool verbose) {
  ASSERT_TRUE(test::all_layers_finite(r));
  const Expected e = expected_virtual_foreground(v);
  const Measured m = measure(r);
  if (verbose) {
    print_profile("virtual f/1.4 foreground at 0.4 m over a sharp real edge at 2 m", e, m, v.u0);
  }
  const Errors err = errors(m, e);
  std::printf("blur radius %.3f px; max |measured - thin-lens expectation| over the columns:\n"
              "  mask %.5f, I_m %.5f, I_r %.5f, depth %.5f m, composite %.5f\n"
              "  equation (4) against a camera seeing a real occluder (gain %.1f): %.5f\n",
              v.rho, err.mask, err.mixed, err.real, err.depth, err.composite, kCameraGain,
              err.method);
  EXPECT_LT(err.mask, tolerance);
  EXPECT_LT(err.mixed, tolerance);
  EXPECT_LT(err.real, tolerance);
  EXPECT_LT(err.depth, 2.0 * tolerance); // depth spans 1.6 m, not 1
  EXPECT_LT(err.composite, tolerance);

  // The real edge shows through the blurred rim: across it, I_m steps by the
  // uncovered fraction of the background step, as the lens would show it.
  const int left = int(v.edge) - 1, right = int(v.edge) + 1;
  const double step = m.mixed[right] - m.mixed[left];
  const double step_expected = e.mixed[right] - e.mixed[left];
  std::printf("  through the rim (M %.3f .. %.3f) the background edge steps I_m by %.4f "
              "(expected %.4f, unoccluded %.4f)\n",
              m.mask[left], m.mask[right], step, step_expected,
              double(kBackgroundBright - kBackgroundDark));
  EXPECT_GT(m.mask[left], 0.2);
  EXPECT_GT(step, 0.2);
  EXPECT_NEAR(step, step_expected, 2.0 * tolerance);
}

TEST(DepthEdges, BlurredVirtualForegroundOverSharpRealEdgeOnCpu) {
  VirtualForeground v = virtual_foreground_scene();
  v.scene.plate = plate_from(expected_virtual_foreground(v).real);
  check_virtual_foreground(test::render_cpu(v.scene, 256), v, kCpuTolerance, true);
}

TEST(DepthEdges, BlurredVirtualForegroundOverSharpRealEdgeOnGpu) {
  CAMHEAD_REQUIRE_VULKAN();
  VirtualForeground v = virtual_foreground_scene();
  v.scene.plate = plate_from(expected_virtual_foreground(v).real);
  check_virtual_foreground(test::render_gpu(v.scene, 64), v, 0.02, false);
}

// ---------------------------------------------------------------- real in front of virtual

constexpr float kRealForegroundRadiance = 0.3f;
constexpr float kVirtualBehindRadiance = 0.9f;
constexpr float kFarBackgroundRadiance = 0.5f;
constexpr float kFarBackgroundM = 4.0f;

// A real half-plane (x < 0) at 0.4 m, blurred, in front of a sharp virtual
// half-plane at the focus depth (x > its edge), with a uniform real wall at
// 4 m behind both.
struct RealForeground {
  Scene scene;
  double u0 = 0.0, edge = 0.0, rho = 0.0;
};

RealForeground real_foreground_scene() {
  RealForeground v;
  v.scene = test::empty_scene("real_foreground", kFNumber, kFocusM, kWidth, kHeight);
  const int near = stability::add_emitter(v.scene, "real_near", kRealForegroundRadiance);
  const int paint = stability::add_emitter(v.scene, "virtual", kVirtualBehindRadiance);
  const int wall = stability::add_emitter(v.scene, "real_wall", kFarBackgroundRadiance);
  v.u0 = 0.5 * kWidth;
  // The panel's edge lies left of the occluder's projection, where the rim
  // covers more than half of the aperture.
  v.edge = v.u0 - kBackgroundEdgeOffsetPx;
  const float x_edge = float(-kBackgroundEdgeOffsetPx * kFocusM / stability::focal_px(v.scene));
  stability::add_half_plane(v.scene, "real_occluder", kForegroundM, 0.0f, -1, near, true);
  stability::add_half_plane(v.scene, "virtual_panel", kFocusM, x_edge, +1, paint, false);
  stability::add_half_plane(v.scene, "real_wall", kFarBackgroundM, 0.0f, 0, wall, true);
  v.rho = stability::blur_radius_px(v.scene, kForegroundM);
  return v;
}

Expected expected_real_foreground(const RealForeground &v) {
  const auto coverage = [&](double p) { return stability::edge_coverage(p, v.u0, v.rho); };
  const auto behind = [&](double p) { return p > v.edge ? 1.0 : 0.0; }; // virtual panel there
  Expected e;
  for (int i = 0; i < kWidth; ++i) {
    e.mask.push_back(
        stability::pixel_average(i, [&](double p) { return (1.0 - coverage(p)) * behind(p); }));
    e.mixed.push_back(stability::pixel_average(i, [&](double p) {
      const double a = coverage(p);
      return a * kRealForegroundRadiance + (1.0 - a) * (behind(p) * kVirtualBehindRadiance +
                                                        (1.0 - behind(p)) * kFarBackgroundRadiance);
    }));
    e.real.push_back(stability::pixel_average(i, [&](double p) {
      return coverage(p) * kRealForegroundRadiance + (1.0 - coverage(p)) * kFarBackgroundRadiance;
    }));
    e.depth.push_back(stability::pixel_average(i, [&](double p) {
      const double a = coverage(p);
      return a * kForegroundM +
             (1.0 - a) * (behind(p) * kFocusM + (1.0 - behind(p)) * kFarBackgroundM);
    }));
    e.physical.push_back(stability::pixel_average(i, [&](double p) {
      const double a = coverage(p);
      return a * kCameraGain * kRealForegroundRadiance +
             (1.0 - a) * (behind(p) * kVirtualBehindRadiance +
                          (1.0 - behind(p)) * kCameraGain * kFarBackgroundRadiance);
    }));
  }
  fill_composite(e);
  return e;
}

TEST(DepthEdges, BlurredRealForegroundOverSharpVirtualEdgeOnCpu) {
  RealForeground v = real_foreground_scene();
  const Expected e = expected_real_foreground(v);
  v.scene.plate = plate_from(e.real);
  const RenderResult r = test::render_cpu(v.scene, 256);
  ASSERT_TRUE(test::all_layers_finite(r));
  const Measured m = measure(r);
  print_profile("real f/1.4 foreground at 0.4 m over a sharp virtual edge at 2 m", e, m, v.u0);
  const Errors err = errors(m, e);
  // Equation (4) at partial coverage: where the virtual panel is behind the
  // real rim, I_f - physical = A (1 - A)(gain - 1)(wall - foreground) per point.
  const double method_bound =
      0.25 * (kCameraGain - 1.0) * std::abs(kFarBackgroundRadiance - kRealForegroundRadiance);
  std::printf("blur radius %.3f px; max |measured - thin-lens expectation| over the columns:\n"
              "  mask %.5f, I_m %.5f, I_r %.5f, depth %.5f m, composite %.5f\n"
              "  equation (4) against a camera seeing a real panel (gain %.1f): %.5f "
              "(bound A(1-A)(gain-1)|wall-foreground| = %.5f)\n",
              v.rho, err.mask, err.mixed, err.real, err.depth, err.composite, kCameraGain,
              err.method, method_bound);
  EXPECT_LT(err.mask, kCpuTolerance);
  EXPECT_LT(err.mixed, kCpuTolerance);
  EXPECT_LT(err.real, kCpuTolerance);
  EXPECT_LT(err.depth, 0.04); // depth spans 3.6 m
  EXPECT_LT(err.composite, kCpuTolerance);
  EXPECT_LE(err.method, method_bound + 1e-9);

  // The virtual panel shows through the real rim in proportion to the
  // aperture that sees past the foreground: where the rim covers half the
  // aperture, half the panel.
  int half = int(v.edge) + 1;
  for (int i = half; i < kWidth; ++i) {
    if (std::abs(e.mask[i] - 0.5) < std::abs(e.mask[half] - 0.5)) {
      half = i;
    }
  }
  std::printf("  through the real rim at column %d the virtual panel has coverage M = %.4f "
              "(expected %.4f)\n",
              half, m.mask[half], e.mask[half]);
  EXPECT_NEAR(m.mask[half], e.mask[half], kCpuTolerance);
}

} // namespace
} // namespace camhead
