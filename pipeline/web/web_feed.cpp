#include "web_feed.h"

#include <cstring>

namespace camhead::pipeline::web {
namespace {

FrameCopy copy_for(const base::VideoFormat &format) {
  FrameCopy copy;
  copy.format = format;
  copy.bytes.assign(base::frame_bytes(format), 0);
  return copy;
}

} // namespace

WebFeed::WebFeed(const base::VideoFormat &composite, const base::VideoFormat &camera)
    : frames_{LatestValue<FrameCopy>(copy_for(composite)),
              LatestValue<FrameCopy>(copy_for(camera))} {}

void WebFeed::composite(std::uint64_t output_frame, const FrameRecord &record,
                        std::int64_t output_ns, std::span<const std::uint8_t> image) {
  entries_.push({FeedEntry::Kind::composite, output_frame, output_ns, record});
  copy(View::composite, output_frame, image);
}

void WebFeed::filler(std::uint64_t output_frame, FeedEntry::Kind kind, std::int64_t output_ns) {
  entries_.push({kind, output_frame, output_ns, {}});
}

void WebFeed::camera(std::uint64_t sequence, const base::VideoFormat &format,
                     std::span<const std::uint8_t> frame) {
  if (format == frames_[int(View::camera)].back().format)
    copy(View::camera, sequence, frame);
}

void WebFeed::copy(View view, std::uint64_t frame, std::span<const std::uint8_t> image) {
  if (watchers_[int(view)].load(std::memory_order_relaxed) <= 0)
    return;
  FrameCopy &to = frames_[int(view)].back();
  if (image.size() < to.bytes.size())
    return;
  std::memcpy(to.bytes.data(), image.data(), to.bytes.size());
  to.frame = frame;
  to.valid = true;
  frames_[int(view)].publish();
}

void WebFeed::watch(View view, int delta) {
  watchers_[int(view)].fetch_add(delta, std::memory_order_relaxed);
}

bool WebFeed::take_frame(View view) {
  return frames_[int(view)].take();
}

const FrameCopy &WebFeed::frame(View view) const {
  return frames_[int(view)].front();
}

} // namespace camhead::pipeline::web
