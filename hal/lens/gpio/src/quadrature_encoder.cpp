// Reading assembly over an edge source and per-axis decoders. See
// quadrature_encoder.h for what is emitted and how failures are handled.
#include "camhead/hal/lens/gpio/quadrature_encoder.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace camhead::hal::lens::gpio {
namespace {

constexpr std::int64_t to_ns(std::chrono::milliseconds d) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(d).count();
}

} // namespace

QuadratureEncoder::QuadratureEncoder(std::unique_ptr<EdgeSource> source, const AxisConfigs &axes,
                                     QuadratureEncoderOptions options)
    : source_(std::move(source)), options_(options) {
  if (!source_) {
    throw std::invalid_argument("quadrature encoder: no edge source");
  }
  axes_ = source_->axes();
  for (std::size_t i = 0; i < kLensAxisCount; ++i) {
    decoders_[i] = QuadratureDecoder(axes[i]);
  }
  edges_.reserve(256);
  if (!connect() && options_.require_device_at_start) {
    throw std::runtime_error(error_);
  }
}

void QuadratureEncoder::poll(std::chrono::milliseconds timeout, std::vector<EncoderReading> &out) {
  if (connected_ && emit_pending_) {
    emit_if_changed(out); // the connect reading from the constructor: no wait
    return;
  }
  if (!connected_) {
    // No device: wait for the next reopen attempt, but never past `timeout`.
    const std::int64_t now = source_->now_ns();
    if (now < next_open_ns_) {
      source_->sleep_for(std::chrono::nanoseconds(std::min(next_open_ns_ - now, to_ns(timeout))));
      if (source_->now_ns() < next_open_ns_) {
        return;
      }
    }
    if (connect()) {
      emit_if_changed(out); // the connect reading; no wait, a reading is ready
    }
    return;
  }

  edges_.clear();
  std::string error;
  const bool ok = source_->wait_edges(timeout, edges_, error);
  feed(edges_);
  if (!ok) {
    disconnect(error);
  } else if (edges_.empty() && options_.resync_when_idle) {
    resync_when_idle();
  }
  emit_if_changed(out);
}

EncoderStatus QuadratureEncoder::status() const {
  EncoderStatus s;
  s.connected = connected_;
  s.readings = readings_;
  s.reconnects = reconnects_;
  for (std::size_t i = 0; i < kLensAxisCount; ++i) {
    if (axes_[i]) {
      s.missed_edges += decoders_[i].counters().missed_edges;
      s.lost += decoders_[i].counters().recovered;
    }
  }
  if (!connected_) {
    s.detail =
        error_ + "; reopening every " + std::to_string(options_.reopen_interval.count()) + " ms";
    return s;
  }
  // "gpio gpiochip0: connected; focus 1234 homed, zoom -25 not homed"
  s.detail = source_->name() + ": connected;";
  const char *separator = " ";
  for (std::size_t i = 0; i < kLensAxisCount; ++i) {
    if (!axes_[i]) {
      continue;
    }
    const QuadratureDecoder &d = decoders_[i];
    s.detail += separator;
    s.detail += to_string(static_cast<LensAxis>(i));
    s.detail += ' ' + std::to_string(d.position());
    if (d.config().counts_at_index) {
      s.detail += d.homed() ? " homed" : " not homed";
    }
    separator = ", ";
  }
  return s;
}

bool QuadratureEncoder::connect() {
  std::string error;
  AllLevels levels{};
  std::int64_t t_ns = 0;
  if (!source_->open(error)) {
    disconnect(error);
    return false;
  }
  if (!source_->read_levels(levels, t_ns, error)) {
    disconnect(error);
    return false;
  }
  for (std::size_t i = 0; i < kLensAxisCount; ++i) {
    if (!ever_connected_) {
      decoders_[i].reset(levels[i]);
    } else {
      // Edges during the gap are gone: keep counting from here, unhomed.
      decoders_[i].resync(levels[i]);
    }
  }
  if (ever_connected_) {
    ++reconnects_;
  }
  ever_connected_ = connected_ = true;
  emit_pending_ = true;
  last_move_t_ns_ = t_ns;
  error_.clear();
  return true;
}

void QuadratureEncoder::disconnect(const std::string &why) {
  source_->close();
  connected_ = false;
  error_ = why;
  next_open_ns_ = source_->now_ns() + to_ns(options_.reopen_interval);
}

void QuadratureEncoder::feed(std::span<const EdgeEvent> events) {
  for (const EdgeEvent &e : events) {
    const std::size_t i = index(e.axis);
    if (i < kLensAxisCount && axes_[i] && decoders_[i].on_edge(e.line, e.level, e.t_ns)) {
      last_move_t_ns_ = e.t_ns;
    }
  }
}

void QuadratureEncoder::resync_when_idle() {
  AllLevels levels{};
  std::int64_t t_ns = 0;
  std::string error;
  if (!source_->read_levels(levels, t_ns, error)) {
    disconnect(error);
    return;
  }
  bool differs = false;
  for (std::size_t i = 0; i < kLensAxisCount; ++i) {
    differs = differs || (axes_[i] && decoders_[i].levels() != levels[i]);
  }
  if (!differs) {
    const std::int64_t still = to_ns(options_.still_interval);
    if (still > 0 && t_ns - last_emitted_t_ns_ >= still) {
      emit_pending_ = true; // the counts again, as of this re-read
      last_move_t_ns_ = t_ns;
    }
    return;
  }
  // An edge just after the wait timed out shows in the levels before its
  // event is read: when events are waiting, they explain the difference.
  edges_.clear();
  const bool ok = source_->wait_edges(std::chrono::milliseconds(0), edges_, error);
  feed(edges_);
  if (!ok) {
    disconnect(error);
    return;
  }
  if (!edges_.empty()) {
    return;
  }
  for (std::size_t i = 0; i < kLensAxisCount; ++i) {
    if (!axes_[i]) {
      continue;
    }
    const std::int32_t before = decoders_[i].position();
    decoders_[i].observe(levels[i], t_ns);
    if (decoders_[i].position() != before) {
      last_move_t_ns_ = t_ns;
    }
  }
}

void QuadratureEncoder::emit_if_changed(std::vector<EncoderReading> &out) {
  bool changed = emit_pending_;
  for (std::size_t i = 0; i < kLensAxisCount; ++i) {
    changed = changed || (axes_[i] && decoders_[i].position() != emitted_[i]);
  }
  if (!changed) {
    return;
  }
  EncoderReading r;
  r.t_ns = last_move_t_ns_;
  bool any = false;
  for (std::size_t i = 0; i < kLensAxisCount; ++i) {
    if (!axes_[i]) {
      continue;
    }
    emitted_[i] = decoders_[i].position();
    // An axis that homes on its index counts from wherever it was switched
    // on until then: those counts mean nothing to an absolute lens profile.
    if (decoders_[i].config().counts_at_index && !decoders_[i].homed()) {
      continue;
    }
    any = true;
    switch (static_cast<LensAxis>(i)) {
    case LensAxis::focus:
      r.focus = emitted_[i];
      break;
    case LensAxis::iris:
      r.iris = emitted_[i];
      break;
    case LensAxis::zoom:
      r.zoom = emitted_[i];
      break;
    }
  }
  emit_pending_ = false;
  if (!any) {
    return;
  }
  last_emitted_t_ns_ = r.t_ns;
  out.push_back(r);
  ++readings_;
}

} // namespace camhead::hal::lens::gpio
