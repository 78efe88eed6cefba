// One opening of a V4L2 capture device, from open() to close: the checks and
// negotiation of v4l2_camera.h, the mmap buffers, and the ioctls on them.
// The camera makes a new one each time it (re)opens the device. After a
// loss the device is closed at once (so that a driver can let it go) while
// the buffers the caller still holds stay mapped until it releases them.
//
// Thread safety: none of its own; V4l2Camera guards it (see there).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <linux/videodev2.h>

#include "camhead/base/video_format.h"
#include "camhead/hal/jpeg/jpeg_frame.h"
#include "camhead/hal/v4l2/device_file.h"

namespace camhead::hal::camera {

struct StreamRequest {
  std::string device;
  base::PixelFormat format = base::PixelFormat::yuyv;
  int width = 0;
  int height = 0;
  double fps = 0;
  int buffers = 4;
  bool mjpeg = false; // ask for MJPEG, deliver rgb24 (v4l2_camera.h)
};

class CaptureStream {
public:
  // Opens, negotiates, maps, queues every buffer and starts streaming.
  // Empty with `error`, the reason without the device's name.
  [[nodiscard]] static std::unique_ptr<CaptureStream> open(const StreamRequest &request,
                                                           std::string &error);

  ~CaptureStream(); // stops streaming, unmaps, closes
  CaptureStream(const CaptureStream &) = delete;
  CaptureStream &operator=(const CaptureStream &) = delete;

  [[nodiscard]] const base::VideoFormat &format() const { return format_; }
  [[nodiscard]] std::int64_t interval_ns() const { return interval_ns_; }
  // "vivid 'vivid-000-vid-cap', 4 buffers, 25 fps" and what was noticed
  // (a rate the driver cannot set), for the status line.
  [[nodiscard]] const std::string &summary() const { return summary_; }
  [[nodiscard]] int fd() const { return file_.fd(); }
  [[nodiscard]] bool is_open() const { return file_.is_open(); }
  [[nodiscard]] int buffer_count() const { return static_cast<int>(buffers_.size()); }
  // The frame in buffer `index`: the mapped buffer, or its decoded copy for
  // a compressed stream.
  [[nodiscard]] std::span<const std::uint8_t> bytes(int index) const;
  // MJPEG: frames arrive compressed and decode() makes them rgb24.
  [[nodiscard]] bool compressed() const { return mjpeg_; }
  // Decodes buffer `index` (bytesused of it) into its rgb24 copy; false with
  // the reason.
  [[nodiscard]] bool decode(int index, std::uint32_t bytesused, std::string &error);

  enum class Dequeued { buffer, nothing, failed };
  // VIDIOC_DQBUF, non-blocking; `failed` leaves errno set.
  [[nodiscard]] Dequeued dequeue(v4l2_buffer &buffer);
  // VIDIOC_QBUF of buffer `index`; false with errno set.
  [[nodiscard]] bool queue(int index);

  // V4L2_CID_EXPOSURE_ABSOLUTE in ns; false where the driver has none.
  [[nodiscard]] bool read_exposure(std::int64_t &ns) const;

  // Who holds each buffer: the caller from delivery until its release.
  [[nodiscard]] bool held(int index, std::uint64_t sequence) const;
  void hold(int index, std::uint64_t sequence);
  void unhold(int index);
  [[nodiscard]] bool holds_any() const;

  // After a loss: closes the device (which stops the stream) and unmaps the
  // buffers nobody holds; unmap() the others as they come back.
  void close_device();
  void unmap(int index);

private:
  CaptureStream() = default;
  bool negotiate(const StreamRequest &request, std::string &error);
  bool set_rate(double fps, std::string &error);
  bool map_buffers(int count, std::string &error);

  struct Buffer {
    void *address = nullptr;
    std::size_t length = 0;
    bool held = false;
    std::uint64_t sequence = 0;
  };

  v4l2::DeviceFile file_;
  base::VideoFormat format_;
  std::int64_t interval_ns_ = 0;
  std::string summary_;
  std::vector<Buffer> buffers_;
  bool streaming_ = false;
  bool mjpeg_ = false;
  std::vector<std::vector<std::uint8_t>> decoded_; // one rgb24 frame per buffer (MJPEG)
  std::unique_ptr<jpeg::JpegDecoder> jpeg_;        // MJPEG: made at the negotiation
};

} // namespace camhead::hal::camera
