// The Y4M file sink; see file_sink.h.
#include <algorithm>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "camhead/base/partial_file.h"
#include "camhead/hal/output/file/file_sink.h"
#include "camhead/hal/video_file/y4m_header.h"
#include "camhead/hal/video_file/y4m_planes.h"

namespace camhead::hal::output {
namespace {

constexpr std::string_view kFrameLine = "FRAME\n";

class Y4mSink final : public FrameSink {
public:
  Y4mSink(std::string name, base::VideoFormat format, base::PartialFile file)
      : name_(std::move(name)), format_(format), file_(std::move(file)),
        record_(kFrameLine.size() + video_file::y4m_plane_bytes(format)) {
    // Every frame record is "FRAME\n" and the planes: one write each.
    std::copy(kFrameLine.begin(), kFrameLine.end(), record_.begin());
    status_.connected = true;
    status_.detail = this->name() + ": writing " + file_.partial_path().string();
  }

  std::string name() const override { return "file " + name_; }
  base::VideoFormat format() const override { return format_; }

  bool submit(std::span<const std::uint8_t> frame, std::int64_t) override {
    if (closed_ || broken_)
      return fail(closed_ ? "submit after close" : "the file is broken, no more frames");
    if (std::string wrong = wrong_frame_size(frame, format_); !wrong.empty())
      return fail(wrong);
    video_file::frame_to_y4m_planes(frame, format_, std::span(record_).subspan(kFrameLine.size()));
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
    const std::lock_guard lock(mutex_);
    ++status_.frames;
    return true;
  }

  bool close() override {
    if (closed_)
      return fail("closed twice");
    closed_ = true;
    std::string error;
    if (broken_) {
      file_.discard();
      return fail("not written: an earlier write failed and could not be undone");
    }
    if (status().frames == 0) {
      // A run stopped before its first frame (Ctrl-C while it started)
      // must not replace a take with a file no player opens.
      file_.discard();
      return fail("not written: no frame reached it (an earlier file of that name is kept)");
    }
    if (!file_.commit(true, error))
      return fail(error);
    const std::lock_guard lock(mutex_);
    status_.connected = false;
    status_.detail = name() + ": " + std::to_string(status_.frames) + " frames written";
    return true;
  }

  SinkStatus status() const override {
    const std::lock_guard lock(mutex_);
    return status_;
  }

private:
  bool fail(const std::string &reason) {
    const std::lock_guard lock(mutex_);
    ++status_.errors;
    status_.detail = name() + ": " + reason;
    if (closed_ || broken_)
      status_.connected = false;
    return false;
  }

  const std::string name_;
  const base::VideoFormat format_;
  base::PartialFile file_;
  std::vector<std::uint8_t> record_;
  bool closed_ = false;
  bool broken_ = false;

  mutable std::mutex mutex_;
  SinkStatus status_;
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
