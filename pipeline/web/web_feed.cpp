#include "web_feed.h"

namespace camhead::pipeline::web {

WebFeed::WebFeed(const base::VideoFormat &composite, const base::VideoFormat &camera)
    : formats_{composite, camera}, previews_{LatestValue<PreviewImage>(preview_for(composite)),
                                             LatestValue<PreviewImage>(preview_for(camera))} {}

void WebFeed::composite(std::uint64_t output_frame, const FrameRecord &record,
                        std::int64_t output_ns, std::span<const std::uint8_t> image) {
  entries_.push({FeedEntry::Kind::composite, output_frame, output_ns, record});
  shrink(View::composite, output_frame, formats_[0], image);
}

void WebFeed::filler(std::uint64_t output_frame, FeedEntry::Kind kind, std::int64_t output_ns) {
  entries_.push({kind, output_frame, output_ns, {}});
}

void WebFeed::camera(std::uint64_t sequence, const base::VideoFormat &format,
                     std::span<const std::uint8_t> frame) {
  if (format == formats_[int(View::camera)])
    shrink(View::camera, sequence, format, frame);
}

void WebFeed::shrink(View view, std::uint64_t frame, const base::VideoFormat &format,
                     std::span<const std::uint8_t> image) {
  if (watchers_[int(view)].load(std::memory_order_relaxed) <= 0 ||
      image.size() < base::frame_bytes(format))
    return;
  PreviewImage &preview = previews_[int(view)].back();
  shrink_to_preview(format, image, preview);
  preview.frame = frame;
  previews_[int(view)].publish();
}

void WebFeed::watch(View view, int delta) {
  watchers_[int(view)].fetch_add(delta, std::memory_order_relaxed);
}

bool WebFeed::take_preview(View view) {
  return previews_[int(view)].take();
}

const PreviewImage &WebFeed::preview(View view) const {
  return previews_[int(view)].front();
}

} // namespace camhead::pipeline::web
