// Hardware-lab check of the libcamera camera against vimc (the kernel's
// virtual media-controller camera, which libcamera 0.0.3 has a pipeline
// handler for), through open_libcamera_camera() exactly as the pipeline opens
// one: the loader finds libcamhead_libcamera.so next to this program.
// libcamera_vimc.sh loads vimc and makes the /run/udev/data entries libcamera
// needs without udevd. Prints one RESULT line per verdict:
//
//   libcamera_list          list_libcamera_cameras() names vimc's camera
//   libcamera_adjusted_size 640x480 (vimc gives widths in steps of 6: 636)
//                           fails at open, naming the camera and both
//                           configurations
//   libcamera_capture       480x360 bgr24 (libcamera RGB888, a size vimc takes
//                           unchanged): 3 frames per buffer, no errors
//   libcamera_timestamps    SensorTimestamp: increasing, CLOCK_MONOTONIC (not
//                           ahead of now, at most 2 s old), start of exposure
//   libcamera_sequence      sequence numbers increasing, frames counted
//   libcamera_content       a picture, not one colour
//   libcamera_requeue       holding every buffer stops frames (wait_frame times
//                           out); releasing one brings the next
//   libcamera_rgb_order     rgb24 (libcamera BGR888) by the listed id: the same
//                           picture with red and blue swapped, so the two RGB
//                           formats are mapped the right way round
//
//   camhead_libcamera_vm_check
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdlib>
#include <string>
#include <vector>

#include "camhead/base/monotonic_clock.h"
#include "camhead/hal/camera/libcamera/libcamera_camera.h"
#include "vm_result.h"

namespace {

using namespace camhead::hal::camera;
using camhead::base::monotonic_ns;
using camhead::base::PixelFormat;
using camhead::vm::print_result;
using namespace std::chrono_literals;

constexpr const char *kCameraId = "platform/vimc.0 Sensor B";
constexpr int kWidth = 480;
constexpr int kHeight = 360;
constexpr int kBuffers = 4;

struct Verdict {
  std::string problem; // empty: pass
  std::string detail;
};

void report(const char *name, const Verdict &verdict) {
  print_result(name, verdict.problem.empty(),
               verdict.problem.empty() ? verdict.detail : verdict.problem);
}

// Waits up to 10 s for one frame; a timeout is retried, anything else ends.
bool next_frame(CameraSource &camera, CapturedFrame &frame, std::string &problem) {
  const std::int64_t give_up = monotonic_ns() + 10'000'000'000;
  while (monotonic_ns() < give_up) {
    const CaptureResult result = camera.wait_frame(1000ms, frame);
    if (result == CaptureResult::frame)
      return true;
    if (result != CaptureResult::timeout) {
      problem =
          "wait_frame answered " + std::to_string(int(result)) + ": " + camera.status().detail;
      return false;
    }
  }
  problem = "no frame in 10 s: " + camera.status().detail;
  return false;
}

std::vector<std::uint8_t> copy(const CapturedFrame &frame) {
  return {frame.bytes.begin(), frame.bytes.end()};
}

// Mean absolute difference between channel `a` of one RGB frame and channel
// `b` of another, same size.
double channel_difference(const std::vector<std::uint8_t> &x, int a,
                          const std::vector<std::uint8_t> &y, int b) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i + 2 < x.size() && i + 2 < y.size(); i += 3, ++n)
    sum += std::abs(int(x[i + a]) - int(y[i + b]));
  return n ? sum / double(n) : 0;
}

void check_capture(std::vector<std::uint8_t> &picture) {
  Verdict capture, stamps, sequence, content, requeue;
  std::unique_ptr<CameraSource> camera;
  try {
    camera = open_libcamera_camera({"", PixelFormat::bgr24, kWidth, kHeight, kBuffers});
  } catch (const LibcameraCameraError &e) {
    capture.problem = std::string("open: ") + e.what();
  }
  if (camera) {
    const camhead::base::VideoFormat format = camera->format();
    if (format.pixel != PixelFormat::bgr24 || format.width != kWidth || format.height != kHeight)
      capture.problem = "format " + camhead::base::describe(format);
  }
  const int count = 3 * kBuffers;
  int frames = 0;
  std::int64_t last_stamp = 0;
  std::uint64_t last_sequence = 0;
  while (camera && capture.problem.empty() && frames < count) {
    CapturedFrame frame;
    if (!next_frame(*camera, frame, capture.problem))
      break;
    const std::int64_t now = monotonic_ns();
    if (stamps.problem.empty()) {
      if (frame.timestamp_ns > now || now - frame.timestamp_ns > 2'000'000'000)
        stamps.problem = "stamp " + std::to_string(frame.timestamp_ns) +
                         " is not a recent CLOCK_MONOTONIC time (now " + std::to_string(now) + ")";
      else if (frame.timestamp_ns <= last_stamp)
        stamps.problem = "stamps do not increase";
      else if (frame.mark != TimestampMark::start_of_exposure)
        stamps.problem = "not marked start of exposure";
    }
    if (sequence.problem.empty() && frames > 0 && frame.sequence <= last_sequence)
      sequence.problem =
          "sequence " + std::to_string(frame.sequence) + " after " + std::to_string(last_sequence);
    std::array<bool, 256> seen{};
    for (const std::uint8_t byte : frame.bytes)
      seen[byte] = true;
    const auto values = std::count(seen.begin(), seen.end(), true);
    if (content.problem.empty() && values < 8)
      content.problem = "the picture has " + std::to_string(values) + " byte values";
    picture = copy(frame);
    last_stamp = frame.timestamp_ns;
    last_sequence = frame.sequence;
    ++frames;
    camera->release(frame);
  }

  // Every buffer held: nothing can complete, so no frame may come.
  if (camera && capture.problem.empty()) {
    std::vector<CapturedFrame> held(kBuffers);
    for (CapturedFrame &frame : held)
      if (requeue.problem.empty())
        next_frame(*camera, frame, requeue.problem);
    CapturedFrame extra;
    if (requeue.problem.empty() && camera->wait_frame(400ms, extra) != CaptureResult::timeout)
      requeue.problem = "a frame came while the caller held every buffer";
    for (const CapturedFrame &frame : held)
      if (frame.buffer >= 0)
        camera->release(frame);
    if (requeue.problem.empty() && next_frame(*camera, extra, requeue.problem))
      camera->release(extra);
    frames += kBuffers + 1;
  }

  if (camera) {
    const CameraStatus status = camera->status();
    if (capture.problem.empty() && status.errors != 0)
      capture.problem = std::to_string(status.errors) + " errors: " + status.detail;
    if (sequence.problem.empty() && status.frames != std::uint64_t(frames))
      sequence.problem = "status counts " + std::to_string(status.frames) + " frames, not " +
                         std::to_string(frames);
    capture.detail = std::to_string(frames) + " frames; " + status.detail;
    sequence.detail = "last " + std::to_string(last_sequence) + ", " +
                      std::to_string(status.dropped) + " dropped";
  }
  stamps.detail = "increasing, recent, start of exposure";
  content.detail = "not one colour";
  requeue.detail = std::to_string(kBuffers) + " held: no frame until one was released";
  const std::string &why = capture.problem;
  for (Verdict *v : {&stamps, &sequence, &content, &requeue})
    if (v->problem.empty() && !why.empty())
      v->problem = "no capture: " + why;
  report("libcamera_capture", capture);
  report("libcamera_timestamps", stamps);
  report("libcamera_sequence", sequence);
  report("libcamera_content", content);
  report("libcamera_requeue", requeue);
}

void check_rgb_order(const std::vector<std::uint8_t> &bgr, const std::string &id) {
  Verdict verdict;
  std::vector<std::uint8_t> rgb;
  try {
    std::unique_ptr<CameraSource> camera =
        open_libcamera_camera({id, PixelFormat::rgb24, kWidth, kHeight, kBuffers});
    // The first frames after a start may still be settling: take the third.
    for (int i = 0; i < 3 && verdict.problem.empty(); ++i) {
      CapturedFrame frame;
      if (!next_frame(*camera, frame, verdict.problem))
        break;
      rgb = copy(frame);
      camera->release(frame);
    }
  } catch (const LibcameraCameraError &e) {
    verdict.problem = std::string("open: ") + e.what();
  }
  if (verdict.problem.empty()) {
    if (bgr.size() != rgb.size()) {
      verdict.problem = "the rgb24 frame has " + std::to_string(rgb.size()) +
                        " bytes, the bgr24 one " + std::to_string(bgr.size());
    } else {
      // bgr24 byte 0 is blue, rgb24 byte 2 is blue: swapped channels agree.
      const double swapped =
          (channel_difference(bgr, 0, rgb, 2) + channel_difference(bgr, 2, rgb, 0)) / 2;
      const double same =
          (channel_difference(bgr, 0, rgb, 0) + channel_difference(bgr, 2, rgb, 2)) / 2;
      verdict.detail = "mean difference, red and blue swapped " + std::to_string(swapped) +
                       ", not swapped " + std::to_string(same);
      if (same < 10)
        verdict.problem = "the picture has too little colour to tell (" + verdict.detail + ")";
      else if (swapped * 4 > same)
        verdict.problem =
            "red and blue are not swapped between bgr24 and rgb24 (" + verdict.detail + ")";
    }
  }
  report("libcamera_rgb_order", verdict);
}

} // namespace

int main() {
  Verdict list;
  std::string id = kCameraId;
  try {
    const std::vector<std::string> cameras = list_libcamera_cameras();
    for (const std::string &line : cameras)
      list.detail += (list.detail.empty() ? "" : ", ") + line;
    if (std::none_of(cameras.begin(), cameras.end(), [](const std::string &line) {
          return line.find(kCameraId) != std::string::npos;
        }))
      list.problem = "no " + std::string(kCameraId) + " among: " + list.detail;
  } catch (const LibcameraCameraError &e) {
    list.problem = e.what();
  }
  report("libcamera_list", list);

  Verdict adjusted;
  try {
    (void)open_libcamera_camera({kCameraId, PixelFormat::bgr24, 640, 480, kBuffers});
    adjusted.problem = "640x480 opened, but vimc gives 636x480";
  } catch (const LibcameraCameraError &e) {
    const std::string message = e.what();
    adjusted.detail = message;
    for (const char *word : {kCameraId, "640x480 RGB888", "636x480 RGB888"})
      if (message.find(word) == std::string::npos)
        adjusted.problem = "the error does not name " + std::string(word) + ": " + message;
  }
  report("libcamera_adjusted_size", adjusted);

  std::vector<std::uint8_t> picture;
  check_capture(picture);
  check_rgb_order(picture, id);
  return 0;
}
