// The Y4M file sink; see file_sink.h.
#include <algorithm>
#include <memory>
#include <optional>
#include <vector>

#include "camhead/base/partial_file.h"
#include "camhead/hal/output/file/file_sink.h"
#include "camhead/hal/output/sink_base.h"
#include "camhead/hal/video_file/y4m_header.h"
#include "camhead/hal/video_file/y4m_planes.h"

namespace camhead::hal::output {
namespace {

constexpr std::string_view kFrameLine = "FRAME\n";

class Y4mSink final : public SinkBase {
public:
  Y4mSink(std::string name, base::VideoFormat format, base::PartialFile file)
      : SinkBase(format), name_(std::move(name)), file_(std::move(file)),
        record_(kFrameLine.size() + video_file::y4m_plane_bytes(format)) {
    // Every frame record is "FRAME\n" and the planes: one write each.
    std::copy(kFrameLine.begin(), kFrameLine.end(), record_.begin());
    ready("writing " + file_.partial_path().string());
  }

  std::string name() const override { return "file " + name_; }

private:
  bool send(std::span<const std::uint8_t> frame, std::int64_t) override {
    if (broken_)
      return fail("the file is broken, no more frames");
    video_file::frame_to_y4m_planes(frame, format(), std::span(record_).subspan(kFrameLine.size()));
    const off_t good = file_.size();
    std::string error;
    if (!file_.write(record_, error)) {
      std::string cut_error;
      if (!file_.truncate(good, cut_error)) {
        broken_ = true;
        error += "; " + cut_error;
      }
      return fail(error);
    }
    return true;
  }

  bool finish() override {
    std::string error;
    if (broken_) {
      file_.discard();
      return fail("not written: an earlier write failed and could not be undone");
    }
    if (frames() == 0) {
      // A run stopped before its first frame (Ctrl-C while it started)
      // must not replace a take with a file no player opens.
      file_.discard();
      return fail("not written: no frame reached it (an earlier file of that name is kept)");
    }
    if (!file_.commit(true, error))
      return fail(error);
    return closed(std::to_string(frames()) + " frames written");
  }

  bool writable() const override { return !broken_; }

  const std::string name_;
  base::PartialFile file_;
  std::vector<std::uint8_t> record_;
  bool broken_ = false;
};

} // namespace

std::unique_ptr<FrameSink> open_y4m_sink(const std::filesystem::path &path,
                                         base::VideoFormat format, double fps) {
  const std::string name = path.string();
  if (name.empty())
    throw FileSinkError("Y4M sink: the path is empty");
  if (name == "-")
    throw FileSinkError("-: writing to standard output is not supported; give a file name");
  if (format.pixel != base::PixelFormat::yuyv && format.pixel != base::PixelFormat::nv12)
    throw FileSinkError(name + ": format: " + std::string(base::pixel_format_name(format.pixel)) +
                        " cannot be written as Y4M; use yuyv or nv12");
  const std::string reason = base::check_video_format(format);
  if (!reason.empty())
    throw FileSinkError(name + ": format: " + reason);
  const auto rate = video_file::y4m_rate_from_fps(fps);
  if (!rate)
    throw FileSinkError(name + ": fps: " + std::to_string(fps) + " is not 0.01 to 1000");

  video_file::Y4mHeader header;
  header.width = format.width;
  header.height = format.height;
  header.rate_num = rate->num;
  header.rate_den = rate->den;
  // nv12's chroma is co-sited left, as MPEG-2's: 420mpeg2, not 420jpeg.
  header.chroma = format.pixel == base::PixelFormat::nv12 ? video_file::Y4mChroma::c420mpeg2
                                                          : video_file::Y4mChroma::c422;
  header.range = format.range;
  const std::string line = video_file::format_y4m_header(header);

  std::string error;
  std::optional<base::PartialFile> file = base::PartialFile::create(path, error);
  if (!file)
    throw FileSinkError(name + ": " + error);
  if (!file->write({reinterpret_cast<const std::uint8_t *>(line.data()), line.size()}, error))
    throw FileSinkError(name + ": " + error);
  return std::make_unique<Y4mSink>(name, format, std::move(*file));
}

} // namespace camhead::hal::output
