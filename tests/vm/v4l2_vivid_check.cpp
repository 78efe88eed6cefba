// Hardware-lab check of the V4L2 camera against vivid (the kernel's virtual
// capture driver), through open_v4l2_camera() exactly as the pipeline opens
// a webcam. v4l2_vivid.sh loads vivid with one capture node. Prints one
// RESULT line per verdict:
//
//   v4l2_vivid_yuyv        YUYV 320x180 at 25 fps: frames with CLOCK_MONOTONIC
//                          stamps (increasing, at most 2 s old when received,
//                          at most 200 ms ahead: vivid's end-of-frame stamps),
//                          increasing sequence numbers, a picture that is not
//                          one colour and changes from frame to frame (vivid
//                          prints the time), no errors
//   v4l2_vivid_nv12        the same in NV12 (two planes in one buffer)
//   v4l2_vivid_wrong_size  asking 333x200 fails at open, naming the device and
//                          both sizes (vivid answers the nearest it has)
//   v4l2_vivid_error_buffer vivid's "Inject V4L2_BUF_FLAG_ERROR" button: the
//                          flagged buffer is counted as an error, not delivered,
//                          and frames go on
//   v4l2_vivid_disconnect  vivid's "Disconnect" button (it unregisters the
//                          node, as an unplug does): wait_frame() answers
//                          disconnected, never blocks past its timeout, and
//                          the status names the device
//   v4l2_vivid_reconnect   vivid registers the node again once its last user
//                          has closed it (vivid-core.c, vivid_fop_release), so
//                          the camera, which closed it on the loss, reopens it
//                          by path: frames again, one reconnect counted, the
//                          sequence going on from before
//   v4l2_vivid_reconnect_100  the same 100 times in a row (10 under the
//                          sanitizers): each loss
//                          reported and frames back, with the time from the
//                          loss to the first frame after it (median, worst)
//
//   camhead_v4l2_vivid_check DEVICE
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include "camhead/base/monotonic_clock.h"
#include "camhead/hal/camera/v4l2/v4l2_camera.h"
#include "vm_result.h"

namespace {

// Unplugs in a row (v4l2_vivid_reconnect_100): 100, or 10 in the sanitizer
// build (tests/vm/CMakeLists.txt).
constexpr int kUnplugs = CAMHEAD_LAB_FAULT_CYCLES;

using namespace camhead::hal::camera;
using camhead::base::monotonic_ns;
using camhead::vm::print_result;
using namespace std::chrono_literals;

// vivid's own controls (drivers/media/test-drivers/vivid/vivid-ctrls.c):
// VIVID_CID_VIVID_BASE is 0x00f00000 | 0xf000.
constexpr std::uint32_t kVividDisconnect = 0x00f0f000 + 65;
constexpr std::uint32_t kVividDqbufError = 0x00f0f000 + 66;

// Presses a button control on a second descriptor, closed at once so that
// it does not keep vivid from re-registering after a disconnect.
std::string press(const std::string &device, std::uint32_t id) {
  const int fd = ::open(device.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0)
    return "cannot open " + device + " to press the control";
  v4l2_control control{};
  control.id = id;
  const bool ok = ::ioctl(fd, VIDIOC_S_CTRL, &control) == 0;
  ::close(fd);
  return ok ? std::string() : "VIDIOC_S_CTRL " + std::to_string(id) + " failed";
}

struct Run {
  std::string problem;
  std::uint64_t last_sequence = 0;
  std::int64_t last_stamp = 0;
  int frames = 0;
  std::string mark;
};

// Takes `count` frames and checks each as v4l2_vivid_yuyv says; `run`
// carries the last stamp and sequence on across calls.
void take_frames(CameraSource &camera, int count, Run &run) {
  std::vector<std::uint8_t> previous;
  const std::int64_t give_up = monotonic_ns() + 20'000'000'000;
  while (run.frames < count && run.problem.empty() && monotonic_ns() < give_up) {
    CapturedFrame frame;
    const CaptureResult result = camera.wait_frame(2000ms, frame);
    if (result != CaptureResult::frame) {
      if (result != CaptureResult::timeout)
        run.problem =
            "wait_frame answered " + std::to_string(int(result)) + ": " + camera.status().detail;
      continue;
    }
    const std::int64_t now = monotonic_ns();
    // vivid stamps the end of a frame a frame period ahead (vivid-kthread-cap.c).
    if (frame.timestamp_ns > now + 200'000'000 || now - frame.timestamp_ns > 2'000'000'000)
      run.problem = "stamp " + std::to_string(frame.timestamp_ns) + " is not a recent " +
                    "CLOCK_MONOTONIC time (now " + std::to_string(now) + ")";
    else if (frame.timestamp_ns <= run.last_stamp)
      run.problem = "stamps do not increase";
    else if (run.last_stamp != 0 && frame.sequence <= run.last_sequence)
      run.problem = "sequence " + std::to_string(frame.sequence) + " after " +
                    std::to_string(run.last_sequence);
    std::array<bool, 256> seen{};
    for (const std::uint8_t byte : frame.bytes)
      seen[byte] = true;
    const auto values = std::count(seen.begin(), seen.end(), true);
    if (run.problem.empty() && values < 8)
      run.problem = "the picture has " + std::to_string(values) + " byte values";
    const std::vector<std::uint8_t> bytes(frame.bytes.begin(), frame.bytes.end());
    if (run.problem.empty() && bytes == previous)
      run.problem = "two frames in a row are the same";
    previous = bytes;
    run.last_stamp = frame.timestamp_ns;
    run.last_sequence = frame.sequence;
    run.mark =
        frame.mark == TimestampMark::start_of_exposure ? "start of exposure" : "end of frame";
    ++run.frames;
    camera.release(frame);
  }
  if (run.problem.empty() && run.frames < count)
    run.problem =
        "only " + std::to_string(run.frames) + " of " + std::to_string(count) + " frames in 20 s";
}

std::unique_ptr<CameraSource> open(const std::string &device, camhead::base::PixelFormat format,
                                   int width, int height, std::string &error) {
  try {
    return open_v4l2_camera(V4l2CameraOptions{device, format, width, height, 25, 4});
  } catch (const V4l2CameraError &e) {
    error = e.what();
    return nullptr;
  }
}

void check_format(const std::string &device, camhead::base::PixelFormat format,
                  const std::string &result, int count) {
  std::string error;
  auto camera = open(device, format, 320, 180, error);
  if (!camera) {
    print_result(result, false, error);
    return;
  }
  Run run;
  take_frames(*camera, count, run);
  const CameraStatus status = camera->status();
  if (run.problem.empty() && status.errors != 0)
    run.problem = std::to_string(status.errors) + " errors";
  print_result(result, run.problem.empty(),
               (run.problem.empty() ? "" : run.problem + "; ") +
                   camhead::base::describe(camera->format()) + ", " + std::to_string(run.frames) +
                   " frames, " + std::to_string(status.dropped) + " dropped, stamped at " +
                   run.mark + "; " + status.detail);
}

// The camera unplugged (vivid's Disconnect) and back `count` times: each
// time the loss is reported and frames come again, with the time from the
// loss to the first frame after it (the camera closes the node on the loss,
// vivid registers it again at once, and the camera reopens it on its
// reconnect schedule).
void unplugged_again_and_again(CameraSource &camera, const std::string &device, int count) {
  std::vector<double> back_ms;
  std::string problem;
  const std::uint64_t reconnects_before = camera.status().reconnects;
  for (int k = 0; k < count && problem.empty(); ++k) {
    problem = press(device, kVividDisconnect);
    bool lost = false;
    const std::int64_t give_up = monotonic_ns() + 5'000'000'000;
    while (problem.empty() && !lost && monotonic_ns() < give_up) {
      CapturedFrame frame;
      const CaptureResult result = camera.wait_frame(200ms, frame);
      if (result == CaptureResult::frame)
        camera.release(frame);
      lost = result == CaptureResult::disconnected;
    }
    if (problem.empty() && !lost)
      problem = "unplug " + std::to_string(k + 1) + ": no loss reported within 5 s";
    const std::int64_t lost_at = monotonic_ns();
    bool back = false;
    while (problem.empty() && !back && monotonic_ns() - lost_at < 10'000'000'000) {
      CapturedFrame frame;
      if (camera.wait_frame(200ms, frame) == CaptureResult::frame) {
        camera.release(frame);
        back = true;
      }
    }
    if (problem.empty() && !back)
      problem = "unplug " + std::to_string(k + 1) +
                ": no frame within 10 s of the loss: " + camera.status().detail;
    if (back)
      back_ms.push_back(double(monotonic_ns() - lost_at) * 1e-6);
  }
  const CameraStatus status = camera.status();
  if (problem.empty() && status.reconnects - reconnects_before != std::uint64_t(count))
    problem = std::to_string(status.reconnects - reconnects_before) + " reconnects counted for " +
              std::to_string(count) + " unplugs";
  std::string detail = problem;
  if (!back_ms.empty()) {
    detail += (detail.empty() ? "" : "; ") + std::to_string(back_ms.size()) + " of " +
              std::to_string(count) +
              " back, first frame after the loss: " + camhead::vm::median_and_worst_ms(back_ms) +
              "; " + status.detail;
  }
  print_result("v4l2_vivid_reconnect_100", problem.empty() && int(back_ms.size()) == count, detail);
}

} // namespace

int main(int argc, char **argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: camhead_v4l2_vivid_check DEVICE\n");
    return 2;
  }
  const std::string device = argv[1];
  using camhead::base::PixelFormat;
  check_format(device, PixelFormat::yuyv, "v4l2_vivid_yuyv", 6);
  check_format(device, PixelFormat::nv12, "v4l2_vivid_nv12", 4);

  std::string error;
  auto wrong = open(device, PixelFormat::yuyv, 334, 200, error);
  const bool named = error.find(device + ": asked 334x200 YUYV, the driver answers 320x180 YUYV") !=
                     std::string::npos;
  print_result("v4l2_vivid_wrong_size", !wrong && named, error);

  auto camera = open(device, PixelFormat::yuyv, 320, 180, error);
  if (!camera) {
    for (const char *name :
         {"v4l2_vivid_error_buffer", "v4l2_vivid_disconnect", "v4l2_vivid_reconnect"})
      print_result(name, false, error);
    return 1;
  }
  Run run;
  take_frames(*camera, 2, run);
  // vivid clears the request at the end of the tick that woke us, so a press
  // right after a frame can be lost: pressed a moment later, and again (up
  // to three times) if three frames pass without the error.
  std::string problem = run.problem;
  int presses = 0;
  while (problem.empty() && camera->status().errors == 0 && presses < 3) {
    ::usleep(50'000);
    problem = press(device, kVividDqbufError);
    ++presses;
    take_frames(*camera, run.frames + 3, run);
    if (problem.empty())
      problem = run.problem;
  }
  CameraStatus status = camera->status();
  if (problem.empty() && (status.errors == 0 || status.errors > std::uint64_t(presses)))
    problem = std::to_string(status.errors) + " errors counted after " + std::to_string(presses) +
              " presses";
  print_result("v4l2_vivid_error_buffer", problem.empty(),
               problem + (problem.empty() ? "" : "; ") + std::to_string(status.frames) +
                   " frames, " + std::to_string(status.errors) + " error after " +
                   std::to_string(presses) + " press(es); " + status.detail);

  // Disconnect: every call must come back within its timeout (+ slack).
  problem = press(device, kVividDisconnect);
  bool disconnected = false;
  std::int64_t slowest_ms = 0;
  const std::int64_t give_up = monotonic_ns() + 5'000'000'000;
  while (problem.empty() && !disconnected && monotonic_ns() < give_up) {
    CapturedFrame frame;
    const std::int64_t start = monotonic_ns();
    const CaptureResult result = camera->wait_frame(200ms, frame);
    slowest_ms = std::max(slowest_ms, (monotonic_ns() - start) / 1'000'000);
    if (result == CaptureResult::frame)
      camera->release(frame); // frames already done before the button
    disconnected = result == CaptureResult::disconnected;
  }
  status = camera->status();
  if (problem.empty() && !disconnected)
    problem = "no disconnect reported within 5 s";
  if (problem.empty() && (status.connected || status.detail.find(device) == std::string::npos))
    problem = "status does not say disconnected, naming the device";
  if (problem.empty() && slowest_ms > 700)
    problem = "a wait_frame(200 ms) took " + std::to_string(slowest_ms) + " ms";
  print_result("v4l2_vivid_disconnect", problem.empty(),
               problem + (problem.empty() ? "" : "; ") + "slowest call " +
                   std::to_string(slowest_ms) + " ms; " + status.detail);

  // Reconnect by path, the sequence going on.
  const std::uint64_t before = run.last_sequence;
  Run again;
  again.last_sequence = before;
  again.last_stamp = run.last_stamp;
  const std::int64_t back_by = monotonic_ns() + 10'000'000'000;
  slowest_ms = 0;
  while (problem.empty() && camera->status().reconnects == 0 && monotonic_ns() < back_by) {
    CapturedFrame frame;
    const std::int64_t start = monotonic_ns();
    const CaptureResult result = camera->wait_frame(200ms, frame);
    slowest_ms = std::max(slowest_ms, (monotonic_ns() - start) / 1'000'000);
    if (result == CaptureResult::frame)
      camera->release(frame);
  }
  if (problem.empty())
    take_frames(*camera, 3, again);
  status = camera->status();
  if (problem.empty())
    problem = again.problem;
  if (problem.empty() && (status.reconnects != 1 || !status.connected))
    problem = std::to_string(status.reconnects) + " reconnects, connected " +
              (status.connected ? "yes" : "no");
  if (problem.empty() && slowest_ms > 1500)
    problem = "a wait_frame(200 ms) while reconnecting took " + std::to_string(slowest_ms) + " ms";
  print_result("v4l2_vivid_reconnect", problem.empty(),
               problem + (problem.empty() ? "" : "; ") + "sequence " + std::to_string(before) +
                   " then " + std::to_string(again.last_sequence) + "; " + status.detail);
  if (problem.empty())
    unplugged_again_and_again(*camera, device, kUnplugs);
  else
    print_result("v4l2_vivid_reconnect_100", false, "not run: " + problem);
  return 0;
}
