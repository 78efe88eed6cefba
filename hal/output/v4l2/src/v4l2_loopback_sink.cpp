// The V4L2 loopback sink; see v4l2_loopback_sink.h.
#include "camhead/hal/output/v4l2/v4l2_loopback_sink.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include <linux/videodev2.h>
#include <unistd.h>

#include "camhead/base/monotonic_clock.h"
#include "camhead/hal/output/sink_base.h"
#include "camhead/hal/v4l2/device_file.h"
#include "camhead/hal/v4l2/pixel_formats.h"
#include "camhead/hal/v4l2/reconnect_schedule.h"

namespace camhead::hal::output {
namespace {

using v4l2::errno_text;

struct OpenedDevice {
  v4l2::DeviceFile file;
  base::VideoFormat format;
  std::string summary;
};

// Everything open_v4l2_loopback_sink checks, as a value, so that a reopen
// after a loss repeats it without throwing.
std::optional<OpenedDevice> open_output(const std::string &device, const base::VideoFormat &format,
                                        double fps, std::string &error) {
  OpenedDevice opened;
  opened.file = v4l2::open_device(device, error);
  if (!opened.file.is_open())
    return std::nullopt;
  const auto info = v4l2::query_device(opened.file, error);
  if (!info)
    return std::nullopt;
  const std::string who = info->driver + " '" + info->card + "'";
  if ((info->caps & V4L2_CAP_VIDEO_OUTPUT) == 0) {
    error =
        (info->caps & V4L2_CAP_VIDEO_CAPTURE) != 0
            ? who + " offers video capture only: with exclusive_caps=1 v4l2loopback hides "
                    "its output while another program is writing to it"
            : who + " is not a video output device (it offers " + v4l2::caps_text(info->caps) + ")";
    return std::nullopt;
  }
  if ((info->caps & V4L2_CAP_READWRITE) == 0) {
    error = who + " takes no write() (it offers " + v4l2::caps_text(info->caps) + ")";
    return std::nullopt;
  }

  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  v4l2_pix_format &pix = fmt.fmt.pix;
  pix.width = static_cast<std::uint32_t>(format.width);
  pix.height = static_cast<std::uint32_t>(format.height);
  pix.pixelformat = *v4l2::fourcc_of(format.pixel);
  pix.field = V4L2_FIELD_NONE;
  pix.bytesperline = static_cast<std::uint32_t>(base::row_bytes(format));
  pix.sizeimage = static_cast<std::uint32_t>(base::frame_bytes(format));
  v4l2::set_colour(pix, format);
  const v4l2_pix_format asked = pix;
  if (!opened.file.ioctl(VIDIOC_S_FMT, fmt)) {
    error = "VIDIOC_S_FMT " + v4l2::describe(asked) + ": " + errno_text(errno);
    return std::nullopt;
  }
  if (pix.pixelformat != asked.pixelformat || pix.width != asked.width ||
      pix.height != asked.height) {
    error = "asked " + v4l2::describe(asked) + ", the device answers " + v4l2::describe(pix) +
            " (v4l2loopback keeps the format of a stream that readers still have open)";
    return std::nullopt;
  }
  opened.format = format;
  if (pix.bytesperline > base::row_bytes(format))
    opened.format.stride = static_cast<int>(pix.bytesperline);
  const std::size_t frame = base::frame_bytes(opened.format);
  if (pix.sizeimage != 0 && pix.sizeimage < frame) {
    error = v4l2::describe(pix) + ": the device's frames hold " + std::to_string(pix.sizeimage) +
            " bytes, less than one frame (" + std::to_string(frame) + ")";
    return std::nullopt;
  }
  opened.summary = who + ", " + base::describe(opened.format);

  const v4l2_fract period = *v4l2::frame_period(fps);
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  parm.parm.output.timeperframe = period;
  if (opened.file.ioctl(VIDIOC_S_PARM, parm))
    opened.summary += ", " + v4l2::rate_text(parm.parm.output.timeperframe);
  else
    opened.summary += ", rate not set (VIDIOC_S_PARM " + v4l2::rate_text(period) + ": " +
                      errno_text(errno) + "; readers see the driver's default)";
  // Makes this descriptor v4l2loopback's writer: only a writer that streamed
  // gives the output back when it closes. After write() alone, 0.12.7 with
  // exclusive_caps=1 offers neither capture nor output to anyone until the
  // module is reloaded.
  std::uint32_t type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  if (!opened.file.ioctl(VIDIOC_STREAMON, type)) {
    error = "VIDIOC_STREAMON: " + errno_text(errno);
    return std::nullopt;
  }
  return opened;
}

// Black in `format`: Y' at its floor, Cb and Cr at their zero.
void fill_black(std::span<std::uint8_t> frame, const base::VideoFormat &format) {
  const std::uint8_t y = format.range == base::ColorRange::full ? 0 : 16;
  if (format.pixel == base::PixelFormat::yuyv) {
    for (std::size_t i = 0; i + 1 < frame.size(); i += 2) {
      frame[i] = y;
      frame[i + 1] = 128;
    }
    return;
  }
  const std::size_t luma = base::row_bytes(format) * static_cast<std::size_t>(format.height);
  std::fill(frame.begin(), frame.begin() + static_cast<std::ptrdiff_t>(luma), y);
  std::fill(frame.begin() + static_cast<std::ptrdiff_t>(luma), frame.end(), std::uint8_t{128});
}

class V4l2LoopbackSink final : public SinkBase {
public:
  V4l2LoopbackSink(std::string device, base::VideoFormat asked, double fps, OpenedDevice opened)
      : SinkBase(opened.format), device_(std::move(device)), asked_(asked), fps_(fps),
        file_(std::move(opened.file)) {
    ready("ready, " + opened.summary);
  }

  std::string name() const override { return "v4l2 " + device_; }

private:
  bool send(std::span<const std::uint8_t> frame, std::int64_t) override {
    if (!file_.is_open() && !reopen())
      return false; // skipped while it is away; status() says so
    return write_frame(frame);
  }

  bool finish() override {
    if (!file_.is_open())
      return fail("closed while disconnected: nothing left on the device");
    std::vector<std::uint8_t> black(base::frame_bytes(format()));
    fill_black(black, format());
    const bool written = write_frame(black);
    file_.close();
    if (!written)
      return false;
    return closed("closed after " + std::to_string(frames()) + " frames, left showing black");
  }

  bool writable() const override { return file_.is_open(); }

  // One write() is one frame to v4l2loopback: never split, never resumed.
  bool write_frame(std::span<const std::uint8_t> frame) {
    ssize_t n = 0;
    do {
      n = ::write(file_.fd(), frame.data(), frame.size());
    } while (n < 0 && errno == EINTR);
    if (n == static_cast<ssize_t>(frame.size()))
      return true;
    if (n >= 0)
      return fail("short write: " + std::to_string(n) + " of " + std::to_string(frame.size()) +
                  " bytes taken");
    const int err = errno;
    if (err == EAGAIN)
      return fail("the device is busy; frame skipped");
    if (v4l2::is_device_gone(err) || err == EIO) {
      file_.close();
      schedule_.lost(base::monotonic_ns());
      return fail("write: " + errno_text(err) + "; disconnected, reopening every 0.25 s");
    }
    return fail("write: " + errno_text(err));
  }

  bool reopen() {
    const std::int64_t now = base::monotonic_ns();
    if (!schedule_.due(now))
      return false;
    std::string error;
    std::optional<OpenedDevice> opened = open_output(device_, asked_, fps_, error);
    if (opened && opened->format != format()) {
      error = "it is back but takes " + base::describe(opened->format) + ", not " +
              base::describe(format());
      opened.reset();
    }
    if (!opened) {
      schedule_.failed(now);
      return away("disconnected, reopening every 0.25 s; last try: " + error);
    }
    schedule_.succeeded();
    file_ = std::move(opened->file);
    ready("reconnected, " + opened->summary);
    return true;
  }

  const std::string device_;
  const base::VideoFormat asked_;
  const double fps_;
  v4l2::DeviceFile file_;
  v4l2::ReconnectSchedule schedule_;
};

} // namespace

std::unique_ptr<FrameSink> open_v4l2_loopback_sink(const std::string &device,
                                                   base::VideoFormat format, double fps) {
  if (device.empty())
    throw V4l2SinkError("V4L2 loopback sink: no device named");
  if (format.pixel != base::PixelFormat::yuyv && format.pixel != base::PixelFormat::nv12)
    throw V4l2SinkError(device + ": format: " + std::string(base::pixel_format_name(format.pixel)) +
                        " cannot go to a V4L2 loopback device; use yuyv or nv12");
  if (const std::string reason = base::check_video_format(format); !reason.empty())
    throw V4l2SinkError(device + ": format: " + reason);
  if (!v4l2::frame_period(fps) || fps < 0.01)
    throw V4l2SinkError(device + ": fps: " + std::to_string(fps) + " is not 0.01 to 1000");
  std::string error;
  std::optional<OpenedDevice> opened = open_output(device, format, fps, error);
  if (!opened)
    throw V4l2SinkError(device + ": " + error);
  return std::make_unique<V4l2LoopbackSink>(device, format, fps, std::move(*opened));
}

} // namespace camhead::hal::output
