// A recorded take played as a camera: a Y4M file, or a sequence of PNGs.
//
// What is played, by `path`:
//   a file starting "YUV4MPEG2 "  Y4M; 4:2:0 is delivered as nv12 (Cb and Cr
//                                 interleaved), 4:2:2 as yuyv (packed), bt709,
//                                 the range XCOLORRANGE states (default
//                                 limited). The header is read strictly
//                                 (camhead/hal/video_file/y4m_header.h).
//   a pattern, "take/%05d.png"    frames numbered from 0 or 1 (whichever exists)
//                                 up to the first number that is missing
//   a folder                      every *.png in it, sorted by name
//   a PNG file                    a single frame (with loop: a still camera)
// PNGs are delivered as rgb24 (8-bit sRGB as stored); every frame must have
// the size of the first, at most 16384 pixels a side.
//
// Errors: open_file_camera throws FileCameraError ("FILE: FIELD: REASON")
// for anything it can see at open: an unreadable file, a bad header, a
// first frame that is missing or short. Once open, nothing throws: a frame
// that is short or garbled (or a PNG of another size) is an error that
// status().detail names by file and frame, as
// "take.y4m:frame 12: truncated: 8192 of 622080 bytes", counted in errors.
// A file played once then `failed`: its take is not whole. A looping file
// stands in for a live camera, and goes as a live one that lost its signal
// does: `disconnected` while it waits kRetryAfter, then it plays again from
// the first frame (a reconnect), and so on for as long as it fails.
//
// Timing: the rate is FileCameraOptions::fps, or else the Y4M's F, or 25
// for PNGs. With `realtime`, frame 0 is delivered one interval after the
// first wait_frame() (and after a retry), frame i+1 one interval after frame
// i was due, as a camera delivers a frame once its exposure is over: stamped
// with CLOCK_MONOTONIC when it was due, as the end of an exposure of a whole
// interval (mark end_of_frame), so that its mid-exposure is half a frame in
// the past, as the lens chain has it. The stamps keep the schedule, as a
// sensor's clock does, when the capture thread wakes late to deliver; a
// consumer more than a frame behind restarts the schedule from its call
// rather than getting a burst (a file never drops frames). Without `realtime`, frames
// come as fast as they are asked for and stamps are the first delivery's
// time plus exactly sequence * interval (mark start_of_exposure), so that
// offline runs are reproducible.
// sequence counts every delivered frame from 0, across loops.
//
// Buffers: three, allocated at open. A caller holding all three gets
// `timeout` until it releases one. release() frees a buffer only for the
// frame it holds now: a second release of a frame, a stale one (the buffer
// has since carried a newer frame) or an index that is not ours are ignored
// and not counted, since they are caller bugs with nothing to recover.
//
// Thread safety: as CameraSource (wait_frame from one thread, release and
// status from any).
#pragma once

#include <chrono>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include "camhead/hal/camera/camera_source.h"

namespace camhead::hal::camera {

struct FileCameraOptions {
  std::filesystem::path path;
  bool loop = false;
  bool realtime = true;
  // 0: the file's own rate (Y4M header), 25 for image sequences; otherwise
  // 0.01 to 1000 frames a second.
  double fps = 0;
  // The frame size the caller needs; 0: the file's. A file of another size
  // is refused as soon as its header is read ("take.y4m: size: ..."),
  // before anything of its size is allocated.
  int width = 0, height = 0;
};

// "FILE: FIELD: REASON", e.g. "take.y4m: header: W missing".
class FileCameraError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

inline constexpr int kFileCameraBuffers = 3;

// How long a looping file camera whose frame failed waits before it plays
// again from the first frame.
inline constexpr std::chrono::milliseconds kFileCameraRetryAfter{1000};

[[nodiscard]] std::unique_ptr<CameraSource> open_file_camera(const FileCameraOptions &options);

} // namespace camhead::hal::camera
