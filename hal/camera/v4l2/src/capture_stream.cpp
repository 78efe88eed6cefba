// See capture_stream.h.
#include "capture_stream.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include <sys/mman.h>

#include "camhead/hal/jpeg/jpeg_frame.h"
#include "camhead/hal/v4l2/pixel_formats.h"

namespace camhead::hal::camera {
namespace {

using v4l2::errno_text;
using v4l2::fourcc_text;

constexpr std::uint32_t kCapture = V4L2_BUF_TYPE_VIDEO_CAPTURE;
// A driver's rate within this of the one asked for is that rate (drivers
// round 29.97 to their own fraction).
constexpr double kRateTolerance = 0.005;

constexpr std::uint32_t kListedFormats = 12;

// "YUYV, MJPG" as VIDIOC_ENUM_FMT lists them, for messages.
std::string offered_formats(const v4l2::DeviceFile &file, bool &offers_jpeg) {
  std::string text;
  offers_jpeg = false;
  for (std::uint32_t i = 0; i < 64; ++i) {
    v4l2_fmtdesc desc{};
    desc.index = i;
    desc.type = kCapture;
    if (!file.ioctl(VIDIOC_ENUM_FMT, desc))
      break;
    offers_jpeg = offers_jpeg || v4l2::is_jpeg(desc.pixelformat);
    // vivid lists 70: the first dozen say enough.
    if (i < kListedFormats)
      text += (text.empty() ? "" : ", ") + fourcc_text(desc.pixelformat);
    else if (i == kListedFormats)
      text += ", ...";
  }
  return text;
}

std::string busy_or(const std::string &ioctl_name, int err) {
  if (err == EBUSY)
    return "is busy: another program is capturing from it (" + ioctl_name + ": " + errno_text(err) +
           ")";
  return ioctl_name + ": " + errno_text(err);
}

} // namespace

std::unique_ptr<CaptureStream> CaptureStream::open(const StreamRequest &request,
                                                   std::string &error) {
  std::unique_ptr<CaptureStream> stream(new CaptureStream());
  stream->file_ = v4l2::open_device(request.device, error);
  if (!stream->file_.is_open())
    return nullptr;
  const auto info = v4l2::query_device(stream->file_, error);
  if (!info)
    return nullptr;
  const std::string who = info->driver + " '" + info->card + "'";
  if ((info->caps & V4L2_CAP_VIDEO_CAPTURE) == 0) {
    error = (info->caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE) != 0
                ? who + " captures through the multi-planar API only, which camhead does not "
                        "support yet"
                : who + " is not a video capture device (it offers " + v4l2::caps_text(info->caps) +
                      ")";
    return nullptr;
  }
  if ((info->caps & V4L2_CAP_STREAMING) == 0) {
    error = who + " has no streaming I/O (it offers " + v4l2::caps_text(info->caps) + ")";
    return nullptr;
  }
  if (!stream->negotiate(request, error) || !stream->set_rate(request.fps, error) ||
      !stream->map_buffers(request.buffers, error))
    return nullptr;
  for (int i = 0; i < stream->buffer_count(); ++i) {
    if (!stream->queue(i)) {
      error = "VIDIOC_QBUF: " + errno_text(errno);
      return nullptr;
    }
  }
  std::uint32_t type = kCapture;
  if (!stream->file_.ioctl(VIDIOC_STREAMON, type)) {
    error = busy_or("VIDIOC_STREAMON", errno);
    return nullptr;
  }
  stream->streaming_ = true;
  stream->summary_ = who + ", " + base::describe(stream->format_) + ", " +
                     std::to_string(stream->buffer_count()) + " buffers" + stream->summary_;
  return stream;
}

bool CaptureStream::negotiate(const StreamRequest &request, std::string &error) {
  mjpeg_ = request.mjpeg;
  if (mjpeg_ && !jpeg_) {
    try {
      jpeg_ = std::make_unique<jpeg::JpegDecoder>();
    } catch (const jpeg::JpegError &e) {
      error = e.what();
      return false;
    }
  }
  const auto fourcc =
      mjpeg_ ? std::optional<std::uint32_t>(V4L2_PIX_FMT_MJPEG) : v4l2::fourcc_of(request.format);
  if (!fourcc) {
    error = "format " + std::string(base::pixel_format_name(request.format)) +
            " is not a camera format (yuyv, nv12, rgb24 or bgr24)";
    return false;
  }
  v4l2_format fmt{};
  fmt.type = kCapture;
  fmt.fmt.pix.width = static_cast<std::uint32_t>(request.width);
  fmt.fmt.pix.height = static_cast<std::uint32_t>(request.height);
  fmt.fmt.pix.pixelformat = *fourcc;
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  v4l2_pix_format asked = fmt.fmt.pix;
  if (!file_.ioctl(VIDIOC_S_FMT, fmt)) {
    error = busy_or("VIDIOC_S_FMT " + v4l2::describe(asked), errno);
    return false;
  }
  const v4l2_pix_format &pix = fmt.fmt.pix;
  // Some webcams call their MJPEG "JPEG": the same frames.
  const bool same_format = pix.pixelformat == *fourcc || (mjpeg_ && v4l2::is_jpeg(pix.pixelformat));
  if (!same_format || pix.width != asked.width || pix.height != asked.height ||
      !v4l2::is_whole_frame(pix.field)) {
    bool offers_jpeg = false;
    const std::string offered = offered_formats(file_, offers_jpeg);
    error = "asked " + v4l2::describe(asked) + ", the driver answers " + v4l2::describe(pix);
    if (!offered.empty())
      error += " (it offers " + offered + ")";
    if (!mjpeg_ && (v4l2::is_jpeg(pix.pixelformat) || offers_jpeg))
      error += "; for its MJPEG frames ask for the format mjpeg";
    return false;
  }
  format_.pixel = request.format;
  format_.width = request.width;
  format_.height = request.height;
  if (mjpeg_) {
    // Decoded by stb_image: full-range RGB, packed, whatever the driver's
    // bytesperline and colorimetry fields say of the compressed stream.
    format_.pixel = base::PixelFormat::rgb24;
    format_.stride = 0;
    return true;
  }
  const std::size_t packed = base::packed_stride(format_.pixel, format_.width);
  if (pix.bytesperline != 0 && pix.bytesperline < packed) {
    error = v4l2::describe(pix) + ": bytesperline " + std::to_string(pix.bytesperline) +
            " is shorter than a row (" + std::to_string(packed) + " bytes)";
    return false;
  }
  format_.stride = pix.bytesperline > packed ? static_cast<int>(pix.bytesperline) : 0;
  if (base::is_yuv(format_.pixel)) {
    const auto colour = v4l2::colour_of(pix, error);
    if (!colour)
      return false;
    format_.matrix = colour->matrix;
    format_.range = colour->range;
  }
  if (pix.sizeimage != 0 && pix.sizeimage < base::frame_bytes(format_)) {
    error = v4l2::describe(pix) + ": sizeimage " + std::to_string(pix.sizeimage) +
            " is less than a frame (" + std::to_string(base::frame_bytes(format_)) + " bytes)";
    return false;
  }
  return true;
}

bool CaptureStream::set_rate(double fps, std::string &error) {
  v4l2_streamparm parm{};
  parm.type = kCapture;
  const bool readable = file_.ioctl(VIDIOC_G_PARM, parm);
  const v4l2_fract current = readable ? parm.parm.capture.timeperframe : v4l2_fract{0, 0};
  if (fps <= 0) {
    interval_ns_ = v4l2::period_ns(current);
    summary_ += ", " + v4l2::rate_text(current);
    return true;
  }
  const auto wanted = v4l2::frame_period(fps);
  if (!wanted) {
    error = "fps " + std::to_string(fps) + " is not 0.01 to 1000";
    return false;
  }
  if (!readable || (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME) == 0) {
    // Not settable (v4l2loopback 0.12.7, some capture cards): the source
    // decides. Its own figure where it gives one, else the rate asked for.
    interval_ns_ =
        v4l2::period_ns(current) > 0 ? v4l2::period_ns(current) : v4l2::period_ns(*wanted);
    summary_ += ", " + v4l2::rate_text(v4l2::period_ns(current) > 0 ? current : *wanted) +
                " (the driver cannot set its rate)";
    return true;
  }
  parm.parm.capture.timeperframe = *wanted;
  if (!file_.ioctl(VIDIOC_S_PARM, parm)) {
    error = "VIDIOC_S_PARM " + v4l2::rate_text(*wanted) + ": " + errno_text(errno);
    return false;
  }
  const v4l2_fract got = parm.parm.capture.timeperframe;
  const std::int64_t got_ns = v4l2::period_ns(got);
  const std::int64_t wanted_ns = v4l2::period_ns(*wanted);
  if (got_ns <= 0 ||
      std::abs(static_cast<double>(got_ns - wanted_ns)) > kRateTolerance * wanted_ns) {
    error = "asked " + v4l2::rate_text(*wanted) + ", the driver answers " + v4l2::rate_text(got) +
            " at " + base::describe(format_);
    return false;
  }
  interval_ns_ = got_ns;
  summary_ += ", " + v4l2::rate_text(got);
  return true;
}

bool CaptureStream::map_buffers(int count, std::string &error) {
  v4l2_requestbuffers request{};
  request.count = static_cast<std::uint32_t>(count);
  request.type = kCapture;
  request.memory = V4L2_MEMORY_MMAP;
  if (!file_.ioctl(VIDIOC_REQBUFS, request)) {
    error = errno == EINVAL ? "has no mmap streaming (VIDIOC_REQBUFS: " + errno_text(EINVAL) + ")"
                            : busy_or("VIDIOC_REQBUFS", errno);
    return false;
  }
  // Handles carry the index in 5 bits (v4l2_camera.cpp); VIDEO_MAX_FRAME is 32.
  if (request.count < 2 || request.count > 32) {
    error = "VIDIOC_REQBUFS gave " + std::to_string(request.count) + " buffers (need 2 to 32)";
    return false;
  }
  // A compressed frame is as long as it is; the decoded copies are frames.
  const std::size_t frame = mjpeg_ ? 1 : base::frame_bytes(format_);
  buffers_.resize(request.count);
  if (mjpeg_)
    decoded_.assign(request.count, std::vector<std::uint8_t>(base::frame_bytes(format_)));
  for (std::uint32_t i = 0; i < request.count; ++i) {
    v4l2_buffer buffer{};
    buffer.index = i;
    buffer.type = kCapture;
    buffer.memory = V4L2_MEMORY_MMAP;
    if (!file_.ioctl(VIDIOC_QUERYBUF, buffer)) {
      error = "VIDIOC_QUERYBUF " + std::to_string(i) + ": " + errno_text(errno);
      return false;
    }
    if (buffer.length < frame) {
      error = "buffer " + std::to_string(i) + " holds " + std::to_string(buffer.length) +
              " bytes, less than a frame (" + std::to_string(frame) + ")";
      return false;
    }
    void *address =
        ::mmap(nullptr, buffer.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd(), buffer.m.offset);
    if (address == MAP_FAILED) {
      error = "mmap of buffer " + std::to_string(i) + ": " + errno_text(errno);
      return false;
    }
    buffers_[i].address = address;
    buffers_[i].length = buffer.length;
  }
  return true;
}

CaptureStream::~CaptureStream() {
  if (streaming_ && file_.is_open()) {
    std::uint32_t type = kCapture;
    (void)file_.ioctl(VIDIOC_STREAMOFF, type);
  }
  for (int i = 0; i < buffer_count(); ++i)
    unmap(i);
  file_.close();
}

std::span<const std::uint8_t> CaptureStream::bytes(int index) const {
  if (mjpeg_)
    return decoded_[static_cast<std::size_t>(index)];
  const Buffer &buffer = buffers_[static_cast<std::size_t>(index)];
  return {static_cast<const std::uint8_t *>(buffer.address), base::frame_bytes(format_)};
}

bool CaptureStream::decode(int index, std::uint32_t bytesused, std::string &error) {
  const Buffer &buffer = buffers_[static_cast<std::size_t>(index)];
  const std::span<const std::uint8_t> jpeg(static_cast<const std::uint8_t *>(buffer.address),
                                           std::min<std::size_t>(bytesused, buffer.length));
  return jpeg_->decode_rgb(jpeg, format_.width, format_.height,
                           decoded_[static_cast<std::size_t>(index)], error);
}

CaptureStream::Dequeued CaptureStream::dequeue(v4l2_buffer &buffer) {
  buffer = {};
  buffer.type = kCapture;
  buffer.memory = V4L2_MEMORY_MMAP;
  if (file_.ioctl(VIDIOC_DQBUF, buffer)) {
    if (buffer.index >= buffers_.size()) {
      errno = ERANGE;
      return Dequeued::failed;
    }
    return Dequeued::buffer;
  }
  return errno == EAGAIN ? Dequeued::nothing : Dequeued::failed;
}

bool CaptureStream::queue(int index) {
  v4l2_buffer buffer{};
  buffer.index = static_cast<std::uint32_t>(index);
  buffer.type = kCapture;
  buffer.memory = V4L2_MEMORY_MMAP;
  return file_.ioctl(VIDIOC_QBUF, buffer);
}

bool CaptureStream::read_exposure(std::int64_t &ns) const {
  v4l2_control control{};
  control.id = V4L2_CID_EXPOSURE_ABSOLUTE;
  if (!file_.is_open() || !file_.ioctl(VIDIOC_G_CTRL, control) || control.value <= 0)
    return false;
  ns = std::int64_t{control.value} * 100'000; // the control counts 100 us
  return true;
}

bool CaptureStream::held(int index, std::uint64_t sequence) const {
  if (index < 0 || index >= buffer_count())
    return false;
  const Buffer &buffer = buffers_[static_cast<std::size_t>(index)];
  return buffer.held && buffer.sequence == sequence;
}

void CaptureStream::hold(int index, std::uint64_t sequence) {
  Buffer &buffer = buffers_[static_cast<std::size_t>(index)];
  buffer.held = true;
  buffer.sequence = sequence;
}

void CaptureStream::unhold(int index) {
  buffers_[static_cast<std::size_t>(index)].held = false;
}

bool CaptureStream::holds_any() const {
  for (const Buffer &buffer : buffers_)
    if (buffer.held && buffer.address != nullptr)
      return true;
  return false;
}

void CaptureStream::close_device() {
  // Closing stops the stream and frees the driver's queue; mapped pages stay
  // valid (the mapping holds its own reference) until munmap.
  file_.close();
  streaming_ = false;
  for (int i = 0; i < buffer_count(); ++i)
    if (!buffers_[static_cast<std::size_t>(i)].held)
      unmap(i);
}

void CaptureStream::unmap(int index) {
  Buffer &buffer = buffers_[static_cast<std::size_t>(index)];
  if (buffer.address != nullptr)
    ::munmap(buffer.address, buffer.length);
  buffer.address = nullptr;
  buffer.held = false;
}

} // namespace camhead::hal::camera
