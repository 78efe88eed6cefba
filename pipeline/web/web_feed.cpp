#include "web_feed.h"

#include <algorithm>
#include <cstring>

namespace camhead::pipeline::web {
namespace {

FrameCopy copy_for(const base::VideoFormat &format, bool with_region = false) {
  FrameCopy copy;
  copy.format = format;
  copy.bytes.assign(base::frame_bytes(format), 0);
  if (with_region)
    copy.region_room.resize(
        renderer::max_region_rects(std::uint32_t(format.width), std::uint32_t(format.height)));
  return copy;
}

} // namespace

WebFeed::WebFeed(const base::VideoFormat &composite, const base::VideoFormat &camera)
    : frames_{LatestValue<FrameCopy>(copy_for(composite)), LatestValue<FrameCopy>(copy_for(camera)),
              LatestValue<FrameCopy>(copy_for(composite, true))} {}

void WebFeed::composite(std::uint64_t output_frame, const FrameRecord &record,
                        std::int64_t output_ns, std::span<const std::uint8_t> image,
                        std::span<const renderer::PixelRect> region) {
  entries_.push({FeedEntry::Kind::composite, output_frame, output_ns, record});
  copy(View::composite, output_frame, image);
  copy(View::region, output_frame, image, region);
}

void WebFeed::filler(std::uint64_t output_frame, FeedEntry::Kind kind, std::int64_t output_ns) {
  entries_.push({kind, output_frame, output_ns, {}});
}

void WebFeed::camera(std::uint64_t sequence, const base::VideoFormat &format,
                     std::span<const std::uint8_t> frame) {
  if (format == frames_[int(View::camera)].back().format)
    copy(View::camera, sequence, frame);
}

void WebFeed::copy(View view, std::uint64_t frame, std::span<const std::uint8_t> image,
                   std::span<const renderer::PixelRect> region) {
  if (watchers_[int(view)].load(std::memory_order_relaxed) <= 0)
    return;
  FrameCopy &to = frames_[int(view)].back();
  if (image.size() < to.bytes.size() || region.size() > to.region_room.size())
    return;
  std::memcpy(to.bytes.data(), image.data(), to.bytes.size());
  std::copy(region.begin(), region.end(), to.region_room.begin());
  to.region_size = region.size();
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
