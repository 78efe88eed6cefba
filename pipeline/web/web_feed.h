// What the frame loop hands the operator page (architecture.md: "a
// snapshot of the pipeline's state per frame, never the frame loop"): each
// output frame's record, and, while someone watches, a copy of the
// composite and of the camera frame, which the page shrinks into its
// preview on its own thread (a copy costs the frame loop a fortieth of a
// shrink: bench/RESULTS.md). The frame loop's side copies into storage made
// here, once, and never waits (latest_value.h, spsc_ring.h); the page reads
// at its own pace and loses what it was too slow for, never the other way
// round.
//
// Thread safety: composite() and filler() from the output thread,
// camera() from the render thread, the rest from the page's thread.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "camhead/base/video_format.h"
#include "camhead/renderer/influence_region.h"
#include "latest_value.h"
#include "run/frame_record.h"
#include "spsc_ring.h"

namespace camhead::pipeline::web {

// The composite, the camera frame, and the composite with the pixels the
// tracer did not work on darkened (the influence region).
enum class View { composite = 0, camera = 1, region = 2 };
inline constexpr int kViews = 3;

// A frame as the frame loop handed it over.
struct FrameCopy {
  base::VideoFormat format;
  std::vector<std::uint8_t> bytes; // frame_bytes(format), made once
  std::uint64_t frame = 0;         // composite: the output frame; camera: its sequence
  bool valid = false;              // false until a frame was copied into it
  // The region view's: the frame's traced pixels, the first region_size
  // of room for the most a region holds (sized, not reserved: a copy of
  // the value keeps its size, not its capacity).
  std::vector<renderer::PixelRect> region_room;
  std::size_t region_size = 0;

  [[nodiscard]] std::span<const renderer::PixelRect> region() const {
    return std::span(region_room).first(region_size);
  }
};

// One line of the run's record, as the page's history keeps it.
struct FeedEntry {
  enum class Kind : std::uint8_t { composite, repeat, placeholder };
  Kind kind = Kind::composite;
  std::uint64_t output_frame = 0;
  std::int64_t output_ns = 0;
  FrameRecord record; // a composite's; empty for a repeat or a placeholder
};

class WebFeed {
public:
  // `composite` is the format of the frames composite() gets (the first
  // output's), `camera` the camera's.
  WebFeed(const base::VideoFormat &composite, const base::VideoFormat &camera);

  // Output thread: a composite sent to the outputs as `output_frame`, and
  // the pixels its renderer traced (FrameReport::region).
  void composite(std::uint64_t output_frame, const FrameRecord &record, std::int64_t output_ns,
                 std::span<const std::uint8_t> image, std::span<const renderer::PixelRect> region);
  // Output thread: a repeat or a placeholder sent as `output_frame`.
  void filler(std::uint64_t output_frame, FeedEntry::Kind kind, std::int64_t output_ns);
  // Render thread: the camera frame `sequence` as it came (copied only
  // while someone watches the camera, and only a frame of the camera's format).
  void camera(std::uint64_t sequence, const base::VideoFormat &format,
              std::span<const std::uint8_t> frame);

  // Page thread: how many watch `view` (the frame loop copies frames for a
  // view only while someone does).
  void watch(View view, int delta);
  // Page thread: whether a frame of `view` newer than frame() came; if so,
  // frame() is it.
  bool take_frame(View view);
  [[nodiscard]] const FrameCopy &frame(View view) const;
  // Page thread: the oldest record line not read yet.
  [[nodiscard]] std::optional<FeedEntry> next_entry() { return entries_.pop(); }
  // Record lines the page was too slow for.
  [[nodiscard]] std::uint64_t entries_dropped() const { return entries_.dropped(); }

private:
  void copy(View view, std::uint64_t frame, std::span<const std::uint8_t> image,
            std::span<const renderer::PixelRect> region = {});

  std::atomic<int> watchers_[kViews] = {0, 0, 0};
  LatestValue<FrameCopy> frames_[kViews];
  // Four seconds of frames at 25 fps: the page drains it ten times a second.
  SpscRing<FeedEntry> entries_{100};
};

} // namespace camhead::pipeline::web
