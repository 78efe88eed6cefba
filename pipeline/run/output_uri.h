// `camhead run --output URI` and a board's "outputs": which sink, where, in
// which format.
//
//   v4l2:/dev/videoN[?format=yuyv|nv12]   the V4L2 loopback webcam
//   drm:CARD[:CONNECTOR][?mode=WxH[@Hz]]  HDMI through DRM/KMS (card: card0,
//                                         /dev/dri/card0 or a driver name)
//   file:PATH.y4m[?format=yuyv|nv12]      Y4M video (4:2:2 or 4:2:0)
//   file:DIR/%05d.png                     PNG sequence, one file a frame
//   null                                  nothing (benchmarks)
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "camhead/base/video_format.h"

namespace camhead::pipeline {

class OutputError : public std::runtime_error {
public:
  // "output URI: REASON"
  OutputError(std::string_view uri, const std::string &reason)
      : std::runtime_error(std::string(uri) + ": " + reason) {}
};

enum class OutputKind { v4l2, drm, y4m, png, null };

struct OutputSpec {
  std::string uri;
  OutputKind kind = OutputKind::null;
  std::string target; // device, card or file path / pattern
  base::PixelFormat format = base::PixelFormat::yuyv;
  std::string connector; // drm: empty = the first connected
  std::string mode;      // drm: empty = the connector's preferred mode
};

// Throws OutputError naming the URI and what is wrong with it.
[[nodiscard]] OutputSpec parse_output_uri(std::string_view uri);

// A run's outputs; two on one DRM connector would fight over it and the
// second is refused (files and device nodes are checked with every other
// path of the run: run_paths.h).
[[nodiscard]] std::vector<OutputSpec> parse_output_uris(const std::vector<std::string> &uris);

} // namespace camhead::pipeline
