// A LensEncoder made of an edge source, one QuadratureDecoder per axis the
// source carries, and the reading assembly below. open_gpio_quadrature() and
// open_simulated_quadrature() both build one of these; only the source
// differs (edge_source.h).
//
// Readings: at most one per poll(), carrying the counts of every configured
// axis, when a count changed (edges that cancel within one batch produce
// none), t_ns the timestamp of the last edge that moved a count, i.e. the
// instant the reported counts became true; and, while the encoder is still,
// every still_interval, t_ns the instant the lines were re-read. On every
// (re)connect one reading is queued at once with the counts as they are, so
// that a lens that never moves still has a state. An axis configured to home
// on its index (counts_at_index) is left out of readings until it has homed,
// as the USB board withholds unhomed axes: its counts are relative to
// wherever the lens was at power-up until then.
//
// Failures: the source failing (chip removed, line released) never throws out
// of poll(). The encoder closes the source, reports connected = false with the
// source's message in `detail`, and retries open() every reopen_interval.
// Edges during the gap are lost, so on reconnect the counts carry on from
// where they were but every axis is marked not homed (status().detail says
// which) until its index is seen again.
//
// Status: missed_edges sums the decoders' missed edges (quadrature_decoder.h);
// lost counts steps found by re-reading the lines when idle, i.e. edges whose
// events the kernel never delivered (its per-line queue holds 16).
//
// Thread safety: none. One thread (the lens thread) constructs, polls and
// asks for status, like every LensEncoder backend in hal/lens.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "camhead/hal/lens/gpio/edge_source.h"
#include "camhead/hal/lens/gpio/quadrature_decoder.h"
#include "camhead/hal/lens/lens_encoder.h"

namespace camhead::hal::lens::gpio {

using AxisConfigs = std::array<QuadratureAxisConfig, kLensAxisCount>;

struct QuadratureEncoderOptions {
  std::chrono::milliseconds reopen_interval{1000};
  // When a wait times out without edges, re-read the lines and decode any
  // difference as a full-state observation (QuadratureDecoder::observe).
  bool resync_when_idle = true;
  // A still encoder makes no edges, but the lens state downstream needs to
  // hear that it is still: silence reads as a dropout there, and the last
  // motion would be extrapolated. When an idle re-read confirms the counts
  // and the last reading is older than this, the counts are reported again,
  // stamped with the re-read. Needs resync_when_idle; zero turns it off.
  std::chrono::milliseconds still_interval{20};
  // Throw from the constructor when the first open() fails; false starts
  // disconnected and keeps retrying in poll().
  bool require_device_at_start = true;
};

class QuadratureEncoder final : public LensEncoder {
public:
  // Opens the source. Throws std::runtime_error with the source's message
  // ("gpio gpiochip0 line 17 (focus A): ...") when it cannot, unless
  // options.require_device_at_start is false. axes[i] configures the decoder
  // of axis i; entries for axes the source does not carry are ignored.
  QuadratureEncoder(std::unique_ptr<EdgeSource> source, const AxisConfigs &axes,
                    QuadratureEncoderOptions options = {});

  [[nodiscard]] std::string name() const override { return source_->name(); }
  void poll(std::chrono::milliseconds timeout, std::vector<EncoderReading> &out) override;
  [[nodiscard]] EncoderStatus status() const override;

  [[nodiscard]] const QuadratureDecoder &decoder(LensAxis axis) const {
    return decoders_[index(axis)];
  }
  [[nodiscard]] bool homed(LensAxis axis) const { return decoder(axis).homed(); }
  // The next qualified index of `axis` sets its counts_at_index again.
  void request_home(LensAxis axis) { decoders_[index(axis)].request_home(); }
  [[nodiscard]] bool connected() const { return connected_; }

private:
  static constexpr std::size_t index(LensAxis axis) { return static_cast<std::size_t>(axis); }

  bool connect();
  void disconnect(const std::string &why);
  void feed(std::span<const EdgeEvent> events);
  void resync_when_idle();
  void emit_if_changed(std::vector<EncoderReading> &out);

  std::unique_ptr<EdgeSource> source_;
  QuadratureEncoderOptions options_;
  AxisSet axes_{};
  std::array<QuadratureDecoder, kLensAxisCount> decoders_;
  std::array<std::int32_t, kLensAxisCount> emitted_{};
  std::vector<EdgeEvent> edges_; // reused every poll
  bool connected_ = false;
  bool ever_connected_ = false;
  bool emit_pending_ = false;
  std::int64_t last_move_t_ns_ = 0;    // t_ns of the next reading
  std::int64_t last_emitted_t_ns_ = 0; // t_ns of the last reading
  std::int64_t next_open_ns_ = 0;
  std::uint64_t readings_ = 0, reconnects_ = 0;
  std::string error_; // why the source is closed, while it is
};

} // namespace camhead::hal::lens::gpio
