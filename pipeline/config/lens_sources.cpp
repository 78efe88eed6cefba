#include "config/lens_sources.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>

#include "camhead/hal/lens/gpio/gpio_quadrature.h"
#include "camhead/hal/lens/gpio/simulated_quadrature.h"
#include "camhead/hal/lens/network/freed_receiver.h"
#include "camhead/hal/lens/network/opentrackio_receiver.h"
#include "camhead/hal/lens/trace/lens_trace.h"
#include "camhead/hal/lens/trace/trace_replay.h"
#include "camhead/hal/lens/usb/simulated_usb_lens.h"
#include "camhead/hal/lens/usb/usb_lens.h"
#include "config/trace_curve.h"
#include "tracking/tracker_axes.h"

namespace camhead::pipeline {

namespace {

namespace hl = hal::lens;
using Axis = TraceCurve::Axis;

std::unique_ptr<hl::LensEncoder> open_backend(const TraceSourceConfig &c) {
  hl::TraceReplayOptions options;
  options.loop = c.loop;
  options.speed = c.speed;
  if (c.monotonic_origin)
    options.start_ns = 0;
  return hl::TraceReplay::open(c.file, options);
}

std::unique_ptr<hl::LensEncoder> open_backend(const UsbSourceConfig &c) {
  const hl::UsbLensConfig config{.vid = c.vendor_id, .pid = c.product_id, .serial = c.serial};
  if (!c.simulate)
    return hl::open_usb_lens(config);
  // The simulated board latches its counts from the trace, looping.
  const hl::LensTrace trace = hl::read_lens_trace(*c.simulate);
  // Looping as the trace's own replay does, so that both play one lens.
  const double period_s = double(hl::loop_period_ns(trace)) * 1e-9;
  auto focus = std::make_shared<TraceCurve>(trace, &hl::EncoderReading::focus, period_s);
  auto iris = std::make_shared<TraceCurve>(trace, &hl::EncoderReading::iris, period_s);
  auto zoom = std::make_shared<TraceCurve>(trace, &hl::EncoderReading::zoom, period_s);
  hl::SimulatedUsbLensOptions options;
  options.rate_hz = 200.0;
  options.serial = c.serial.value_or("SIM0001");
  options.trajectory = [focus, iris, zoom](std::uint32_t, double seconds) {
    const auto counts = [seconds](const TraceCurve &curve) {
      return curve.empty() ? 0 : std::int32_t(std::lround(curve.at(seconds)));
    };
    return hl::LensAxes{counts(*focus), counts(*iris), counts(*zoom)};
  };
  return hl::open_simulated_usb_lens(std::make_shared<hl::SimulatedUsbLensBoard>(options), config);
}

hl::gpio::GpioQuadratureAxis gpio_axis(const GpioAxisConfig &a) {
  hl::gpio::GpioQuadratureAxis axis;
  axis.line_a = a.line_a;
  axis.line_b = a.line_b;
  axis.line_index = a.line_index;
  axis.index_active_low = a.index_active_low;
  axis.decoder.reverse = a.reverse;
  axis.decoder.counts_at_index = a.counts_at_index;
  return axis;
}

// The simulated chip has no loop of its own: its edges are computed ahead,
// so the trace is repeated this many times (a minute of the bundled trace).
constexpr int kSimulatedGpioRepeats = 10;
// Edges the simulated chip computes ahead, at most: 4 M, a hundred MB. The
// bundled trace needs 0.4 M; a trace that jumps by 2^32 counts in 61 bytes
// would need every one of those edges.
constexpr double kMaxSimulatedEdges = double(1 << 22);

std::optional<hl::gpio::SimulatedQuadratureAxis>
simulated_axis(const hl::LensTrace &trace, Axis axis, const GpioAxisConfig &a) {
  if (std::none_of(trace.readings.begin(), trace.readings.end(),
                   [axis](const hl::EncoderReading &r) { return bool(r.*axis); }))
    return std::nullopt;
  hl::gpio::SimulatedQuadratureAxis sim;
  sim.decoder.reverse = a.reverse;
  // The trace's counts are absolute; the simulated encoder's index sits at
  // counts_at_index, so the axis homes as a real one does, on passing it.
  sim.decoder.counts_at_index = a.counts_at_index;
  sim.index_count = a.counts_at_index;
  double edges = 0.0;
  std::optional<std::int32_t> last;
  for (const hl::EncoderReading &r : trace.readings)
    if (r.*axis) {
      if (last)
        edges += std::abs(double(*(r.*axis)) - double(*last));
      last = r.*axis;
    }
  if (edges * kSimulatedGpioRepeats > kMaxSimulatedEdges)
    throw hl::TraceError(
        trace.source, 0, "",
        "its counts move " + std::to_string(std::llround(edges)) +
            " in all, more than the simulated GPIO chip follows (" +
            std::to_string(std::llround(kMaxSimulatedEdges / kSimulatedGpioRepeats)) +
            "); a lens moves a few ten thousand");
  const std::int64_t first = trace.readings.front().t_ns;
  const std::int64_t period = hl::loop_period_ns(trace); // as the trace's replay loops
  for (int k = 0; k < kSimulatedGpioRepeats; ++k)
    for (const hl::EncoderReading &r : trace.readings)
      if (r.*axis)
        sim.trajectory.push_back({r.t_ns - first + k * period, double(*(r.*axis))});
  return sim;
}

std::unique_ptr<hl::LensEncoder> open_backend(const GpioSourceConfig &c) {
  if (c.simulate) {
    const hl::LensTrace trace = hl::read_lens_trace(*c.simulate);
    hl::gpio::SimulatedQuadratureConfig config;
    if (c.focus)
      config.focus = simulated_axis(trace, &hl::EncoderReading::focus, *c.focus);
    if (c.iris)
      config.iris = simulated_axis(trace, &hl::EncoderReading::iris, *c.iris);
    if (c.zoom)
      config.zoom = simulated_axis(trace, &hl::EncoderReading::zoom, *c.zoom);
    return hl::gpio::open_simulated_quadrature(config);
  }
  hl::gpio::GpioQuadratureConfig config;
  config.chip = c.chip;
  if (c.focus)
    config.focus = gpio_axis(*c.focus);
  if (c.iris)
    config.iris = gpio_axis(*c.iris);
  if (c.zoom)
    config.zoom = gpio_axis(*c.zoom);
  switch (c.bias) {
  case GpioBias::as_is:
    config.bias = hl::gpio::GpioBias::as_is;
    break;
  case GpioBias::disable:
    config.bias = hl::gpio::GpioBias::disable;
    break;
  case GpioBias::pull_up:
    config.bias = hl::gpio::GpioBias::pull_up;
    break;
  case GpioBias::pull_down:
    config.bias = hl::gpio::GpioBias::pull_down;
    break;
  }
  return hl::gpio::open_gpio_quadrature(config);
}

std::unique_ptr<hl::LensEncoder> open_backend(const FreedSourceConfig &c) {
  return std::make_unique<hl::FreedReceiver>(hl::FreedReceiverConfig{
      .bind_address = c.bind_address, .port = c.port, .camera_id = c.camera_id});
}

std::unique_ptr<hl::LensEncoder> open_backend(const OpenTrackIoSourceConfig &c) {
  hl::OpenTrackIoReceiverConfig config;
  config.bind_address = c.bind_address;
  config.port = c.port;
  config.multicast_group = c.multicast_group.value_or("");
  return std::make_unique<hl::OpenTrackIoReceiver>(config);
}

} // namespace

std::unique_ptr<hal::lens::LensEncoder> open_lens_source(const LensSourceConfig &source) {
  try {
    // One open_backend per kind of source: a kind without one does not compile.
    return std::visit([](const auto &c) { return open_backend(c); }, source.kind);
  } catch (const std::exception &e) {
    throw std::runtime_error("lens source \"" + source.name + "\": " + e.what());
  }
}

lens_control::EncoderSample to_encoder_sample(const hal::lens::EncoderReading &r) {
  return {.t_ns = r.t_ns,
          .focus = r.focus,
          .iris = r.iris,
          .zoom = r.zoom,
          .focus_distance_m = r.focus_distance_m,
          .f_number = r.f_stop,
          .focal_length_mm = r.focal_length_mm};
}

lens_control::LensProfile load_board_profile(const Board &board) {
  return board.lens.profile ? lens_control::LensProfile::load(*board.lens.profile)
                            : lens_control::LensProfile::uncalibrated();
}

namespace {

lens_control::LensTrackerConfig tracker_config(const LensSourceConfig &source) {
  lens_control::LensTrackerConfig config;
  const auto delay_ns = std::int64_t(std::llround(source.delay_ms * 1e6));
  for (lens_control::AxisConfig *axis : {&config.focus, &config.iris, &config.zoom})
    axis->timeline.delay_ns = delay_ns;
  return config;
}

} // namespace

LensChannel::LensChannel(LensSourceConfig config, std::unique_ptr<hal::lens::LensEncoder> encoder,
                         const lens_control::LensProfile &profile)
    : config_(std::move(config)), encoder_(std::move(encoder)),
      tracker_(profile, tracker_config(config_)) {}

std::size_t LensChannel::pump(std::chrono::milliseconds timeout) {
  const std::size_t n = poll(timeout);
  feed();
  return n;
}

std::size_t LensChannel::poll(std::chrono::milliseconds timeout) {
  batch_.clear();
  encoder_->poll(timeout, batch_);
  return batch_.size();
}

void LensChannel::track_pose(PoseType type, double delay_ms) {
  pose_type_ = type;
  poses_.emplace(PoseTimelineParams{.delay_ns = std::llround(delay_ms * 1e6)});
}

void LensChannel::feed() {
  for (const hal::lens::EncoderReading &r : batch_) {
    tracker_.push(to_encoder_sample(r));
    if (poses_ && r.pose)
      (void)poses_->push(r.t_ns, pose_type_ == PoseType::freed ? from_freed(*r.pose)
                                                               : from_opentrackio(*r.pose));
  }
  if (!batch_.empty())
    last_ = batch_.back();
  batch_.clear();
}

std::vector<LensChannel> open_lens_channels(const Board &board) {
  return open_lens_channels(board, load_board_profile(board));
}

std::vector<LensChannel> open_lens_channels(const Board &board,
                                            const lens_control::LensProfile &profile) {
  std::vector<LensChannel> channels;
  for (const LensSourceConfig &source : board.lens.sources)
    channels.emplace_back(source, open_lens_source(source), profile);
  return channels;
}

} // namespace camhead::pipeline
