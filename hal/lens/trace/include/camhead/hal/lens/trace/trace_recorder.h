// Records what a lens source delivers: a LensEncoder decorator that passes
// every reading through unchanged and appends it to a lens trace
// (lens_trace.h), e.g. to capture a focus puller's move on set and replay it
// later against the same plate.
//
// Crash safety: the trace is written to PATH.partial and renamed to PATH by
// close(), so a file that was not finished is recognisable by its name. Rows
// are handed to the kernel (one write of whole lines) whenever the readings
// have advanced by `flush_interval` since the last flush, when a poll brings
// nothing new, and on close: a crashing process loses at most that interval
// of readings. Surviving a power cut as well would need an fsync per flush,
// which an SD card cannot keep up with at 100 Hz; close() syncs once.
//
// Time: row t_s is the reading's t_ns minus that of the first recorded
// reading, so a trace starts at 0. A reading older than the previous one (a
// source whose clock stepped) cannot be a row of a trace; it is passed
// through, not recorded, and counted in skipped().
//
// A write error (disk full) never throws from poll(): recording stops, the
// readings keep flowing, and status().detail says why.
//
// Thread safety: none. One thread (the lens thread) owns a recorder.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camhead/base/partial_file.h"
#include "camhead/hal/lens/lens_encoder.h"

namespace camhead::hal::lens {

struct TraceRecorderOptions {
  std::chrono::milliseconds flush_interval{250};
  std::string comment; // extra comment lines for the file's head (without '#')
};

class TraceRecorder final : public LensEncoder {
public:
  // Creates PATH.partial (replacing a stale one) and writes the head of the
  // trace (base/partial_file.h: a PATH that is a symbolic link stands for
  // its target; one that is a device node, a FIFO or a folder is refused).
  // Throws TraceError naming the file when it cannot.
  TraceRecorder(std::unique_ptr<LensEncoder> inner, std::filesystem::path path,
                TraceRecorderOptions options = {});
  // Writes what is buffered into PATH.partial and leaves it there, PATH
  // untouched: a recorder destroyed without close() (an exception on the
  // way) did not finish its recording, and must not replace the trace a
  // user already had.
  ~TraceRecorder() override;

  // Writes what is buffered, syncs, closes and renames PATH.partial to PATH.
  // Idempotent. Throws TraceError naming the file when any step fails, or
  // when recording had stopped on an earlier write error.
  void close();

  // The inner source's name, so logs keep naming the device.
  [[nodiscard]] std::string name() const override;
  void poll(std::chrono::milliseconds timeout, std::vector<EncoderReading> &out) override;
  // The inner source's status; a write error is appended to its detail.
  [[nodiscard]] EncoderStatus status() const override;

  [[nodiscard]] LensEncoder &inner() { return *inner_; }
  [[nodiscard]] const std::filesystem::path &path() const { return path_; }
  [[nodiscard]] std::filesystem::path partial_path() const;
  [[nodiscard]] std::uint64_t recorded() const { return recorded_; }
  [[nodiscard]] std::uint64_t skipped() const { return skipped_; }

private:
  void record(const EncoderReading &r);
  void flush();
  void fail(const std::string &what);

  std::unique_ptr<LensEncoder> inner_;
  std::filesystem::path path_;
  std::int64_t flush_interval_ns_ = 0;
  std::optional<base::PartialFile> file_;
  std::string pending_;
  std::optional<std::int64_t> origin_ns_, last_ns_;
  std::int64_t last_flush_ns_ = 0;
  std::uint64_t recorded_ = 0, skipped_ = 0;
  std::string error_; // first write error; recording stopped
  bool closed_ = false;
};

} // namespace camhead::hal::lens
