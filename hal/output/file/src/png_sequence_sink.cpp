// The PNG sequence sink; see file_sink.h.
#include <optional>
#include <system_error>
#include <vector>

#include "camhead/base/partial_file.h"
#include "camhead/hal/output/file/file_sink.h"
#include "camhead/hal/output/sink_base.h"
#include "camhead/hal/video_file/frame_pattern.h"
#include "camhead/hal/video_file/png_frame.h"

namespace camhead::hal::output {
namespace {

using video_file::FramePattern;

class PngSequenceSink final : public SinkBase {
public:
  PngSequenceSink(FramePattern pattern, base::VideoFormat format)
      : SinkBase(format), pattern_(std::move(pattern)) {
    ready("ready");
  }

  std::string name() const override { return "png " + pattern_.text(); }

private:
  bool send(std::span<const std::uint8_t> frame, std::int64_t) override {
    const base::VideoFormat f = format();
    if (!video_file::encode_png_rgb(frame, f.width, f.height, base::row_bytes(f), png_))
      return fail("cannot encode PNG (out of memory)");
    const std::filesystem::path target = pattern_.path(next_);
    std::string error;
    std::optional<base::PartialFile> file = base::PartialFile::create(target, error);
    if (!file || !file->write(png_, error) || !file->commit(false, error))
      return fail(target.string() + ": " + error);
    ++next_;
    return true;
  }

  bool finish() override { return closed(std::to_string(frames()) + " frames written"); }

  const FramePattern pattern_;
  std::vector<std::uint8_t> png_;
  std::uint64_t next_ = 0; // frames written, and the next file's number
};

} // namespace

std::unique_ptr<FrameSink> open_png_sequence_sink(const std::string &pattern,
                                                  base::VideoFormat format) {
  std::string error;
  std::optional<FramePattern> parsed = FramePattern::parse(pattern, error);
  if (!parsed)
    throw FileSinkError(pattern + ": " + error);
  if (format.pixel != base::PixelFormat::rgb24)
    throw FileSinkError(pattern +
                        ": format: " + std::string(base::pixel_format_name(format.pixel)) +
                        " cannot be written as PNG; use rgb24");
  const std::string reason = base::check_video_format(format);
  if (!reason.empty())
    throw FileSinkError(pattern + ": format: " + reason);

  const std::filesystem::path first = parsed->path(0);
  const std::filesystem::path folder = first.parent_path();
  std::error_code ec;
  if (!folder.empty() && !std::filesystem::create_directories(folder, ec) && ec)
    throw FileSinkError(pattern + ": cannot create folder " + folder.string() + ": " +
                        ec.message());
  // Proves the folder writable now rather than at the first frame.
  std::optional<base::PartialFile> probe = base::PartialFile::create(first, error);
  if (!probe)
    throw FileSinkError(pattern + ": " + error);
  probe->discard();
  return std::make_unique<PngSequenceSink>(std::move(*parsed), format);
}

} // namespace camhead::hal::output
