// See camera_session.h.
#include "camera_session.h"

#include <optional>
#include <system_error>
#include <utility>

#include <libcamera/color_space.h>
#include <libcamera/formats.h>
#include <libcamera/framebuffer.h>
#include <sys/mman.h>

#include "stream_settings.h"

namespace camhead::hal::camera {
namespace {

namespace settings = libcamera_settings;

// stream_settings.h spells the fourccs without libcamera; these are the ones.
static_assert(libcamera::formats::YUYV.fourcc() == settings::kYuyv);
static_assert(libcamera::formats::NV12.fourcc() == settings::kNv12);
static_assert(libcamera::formats::RGB888.fourcc() == settings::kRgb888);
static_assert(libcamera::formats::BGR888.fourcc() == settings::kBgr888);

std::string errno_text(int negative_errno) {
  return std::error_code(-negative_errno, std::generic_category()).message();
}

settings::StreamShape shape_of(const libcamera::StreamConfiguration &cfg) {
  return {cfg.pixelFormat.fourcc(), static_cast<int>(cfg.size.width),
          static_cast<int>(cfg.size.height)};
}

std::optional<settings::StreamColour> colour_of(const std::optional<libcamera::ColorSpace> &space) {
  if (!space)
    return std::nullopt;
  using Encoding = libcamera::ColorSpace::YcbcrEncoding;
  settings::StreamColour colour;
  switch (space->ycbcrEncoding) {
  case Encoding::None:
    colour.encoding = settings::YcbcrEncoding::none;
    break;
  case Encoding::Rec601:
    colour.encoding = settings::YcbcrEncoding::rec601;
    break;
  case Encoding::Rec709:
    colour.encoding = settings::YcbcrEncoding::rec709;
    break;
  case Encoding::Rec2020:
    colour.encoding = settings::YcbcrEncoding::rec2020;
    break;
  }
  colour.full_range = space->range == libcamera::ColorSpace::Range::Full;
  return colour;
}

} // namespace

std::unique_ptr<CameraSession> CameraSession::create(std::shared_ptr<libcamera::Camera> camera,
                                                     const std::string &label,
                                                     const LibcameraCameraOptions &options,
                                                     std::uint64_t cookie_base,
                                                     std::string &error) {
  std::unique_ptr<CameraSession> session(new CameraSession);
  session->camera_ = std::move(camera);
  libcamera::Camera &cam = *session->camera_;
  const std::string prefix = "libcamera camera " + label + ": ";

  if (const int ret = cam.acquire(); ret < 0) {
    error =
        prefix + "cannot acquire it: " +
        (ret == -EBUSY ? std::string("another process or camera source has it") : errno_text(ret));
    return nullptr;
  }
  session->acquired_ = true;

  session->config_ = cam.generateConfiguration({libcamera::StreamRole::VideoRecording});
  if (!session->config_ || session->config_->size() != 1) {
    error = prefix + "it offers no video-recording stream";
    return nullptr;
  }
  libcamera::StreamConfiguration &cfg = session->config_->at(0);
  const settings::StreamShape asked{*settings::libcamera_fourcc(options.format), options.width,
                                    options.height};
  cfg.pixelFormat = libcamera::PixelFormat(asked.fourcc);
  cfg.size =
      libcamera::Size(static_cast<unsigned>(options.width), static_cast<unsigned>(options.height));
  cfg.bufferCount = static_cast<unsigned>(options.buffers);
  switch (session->config_->validate()) {
  case libcamera::CameraConfiguration::Invalid:
    error =
        prefix + "libcamera refuses " + settings::describe(asked) + " (validate() answers Invalid)";
    return nullptr;
  case libcamera::CameraConfiguration::Adjusted:
    // Another format or size would be another picture than the board asked
    // for; a buffer count, stride or colour space of the pipeline's own is not.
    if (shape_of(cfg) != asked) {
      error = settings::adjusted_message(label, asked, shape_of(cfg));
      return nullptr;
    }
    break;
  case libcamera::CameraConfiguration::Valid:
    break;
  }
  if (const int ret = cam.configure(session->config_.get()); ret < 0) {
    error = prefix + "configure " + cfg.toString() + ": " + errno_text(ret);
    return nullptr;
  }
  session->stream_ = cfg.stream();

  base::VideoFormat &format = session->format_;
  format = {options.format, options.width, options.height, static_cast<int>(cfg.stride)};
  settings::apply_colour(format, colour_of(cfg.colorSpace));
  if (const std::string reason = base::check_video_format(format); !reason.empty()) {
    error = prefix + "the configured stream " + cfg.toString() + " is not a frame: " + reason;
    return nullptr;
  }

  session->allocator_ = std::make_unique<libcamera::FrameBufferAllocator>(session->camera_);
  if (const int ret = session->allocator_->allocate(session->stream_); ret <= 0) {
    error = prefix + "allocating buffers: " + (ret < 0 ? errno_text(ret) : "none given");
    return nullptr;
  }
  const auto &buffers = session->allocator_->buffers(session->stream_);
  for (std::size_t i = 0; i < buffers.size(); ++i) {
    libcamera::FrameBuffer &buffer = *buffers[i];
    std::vector<settings::Plane> planes;
    for (const libcamera::FrameBuffer::Plane &plane : buffer.planes())
      planes.push_back({plane.fd.get(), plane.offset, plane.length});
    std::string why;
    const std::optional<settings::FrameRegion> region = settings::frame_region(planes, format, why);
    if (!region) {
      error = prefix + "buffer " + std::to_string(i) + ": " + why;
      return nullptr;
    }
    void *base = ::mmap(nullptr, region->map_length, PROT_READ, MAP_SHARED, region->fd, 0);
    if (base == MAP_FAILED) {
      error = prefix + "mmap of buffer " + std::to_string(i) + ": " + errno_text(-errno);
      return nullptr;
    }
    session->mappings_.push_back({base, region->map_length, region->frame_offset});

    std::unique_ptr<libcamera::Request> request = cam.createRequest(cookie_base | i);
    if (!request) {
      error = prefix + "createRequest failed";
      return nullptr;
    }
    if (const int ret = request->addBuffer(session->stream_, &buffer); ret < 0) {
      error = prefix + "Request::addBuffer: " + errno_text(ret);
      return nullptr;
    }
    session->requests_.push_back(std::move(request));
  }
  session->summary_ = settings::describe(shape_of(cfg)) + ", stride " + std::to_string(cfg.stride) +
                      ", " + std::to_string(buffers.size()) + " buffers";
  return session;
}

CameraSession::~CameraSession() {
  stop();
  for (const Mapping &mapping : mappings_)
    ::munmap(mapping.base, mapping.length);
  requests_.clear();
  allocator_.reset();
  // Fails (busy) for a disconnected camera, which libcamera never leaves the
  // running state; dropping it then closes its devices.
  if (acquired_)
    camera_->release();
}

std::string CameraSession::start() {
  if (const int ret = camera_->start(); ret < 0)
    return "start: " + errno_text(ret);
  running_ = true;
  for (const std::unique_ptr<libcamera::Request> &request : requests_)
    if (const int ret = camera_->queueRequest(request.get()); ret < 0)
      return "queueRequest: " + errno_text(ret);
  return {};
}

bool CameraSession::stop() {
  if (!running_)
    return true;
  running_ = false;
  if (camera_->stop() == 0)
    return true;
  // A disconnected camera: libcamera 0.0.3 refuses to stop it ("Deal with
  // pending requests if the camera is disconnected" is a todo in camera.cpp)
  // and its queued Requests never complete, the device being gone. A
  // blocking call on the camera's own thread returns once that thread has
  // finished any completion it was delivering, after which nothing there
  // touches the Requests or buffers again and they can be freed. Keeping
  // them instead would keep the camera, whose dead device node libcamera's
  // event loop then polls without pause.
  camera_->invokeMethod(&libcamera::Camera::stop, libcamera::ConnectionTypeBlocking);
  return false;
}

std::string CameraSession::queue(int index) {
  libcamera::Request &request = *requests_[static_cast<std::size_t>(index)];
  request.reuse(libcamera::Request::ReuseBuffers);
  if (const int ret = camera_->queueRequest(&request); ret < 0)
    return "queueRequest: " + errno_text(ret);
  return {};
}

std::span<const std::uint8_t> CameraSession::bytes(int index) const {
  const Mapping &mapping = mappings_[static_cast<std::size_t>(index)];
  return {static_cast<const std::uint8_t *>(mapping.base) + mapping.frame_offset,
          base::frame_bytes(format_)};
}

} // namespace camhead::hal::camera
