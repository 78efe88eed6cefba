// Board files: which devices a rig has and how they are wired (architecture.md,
// board/). One JSON file per board or rig; `sim`, the simulated rig, is the
// default and needs no hardware.
//
//   {
//     "format": "camhead-board", "version": 1, "name": "sim",
//     "description": "...",
//     "lens": {
//       "profile": "../scenes/lenses/example_35mm.json",
//       "sources": [ { "type": "trace", "file": "...", "loop": true } ]
//     }
//   }
//
// Paths inside a board file are relative to the board file. The full field
// list is in board/README.md; the loader checks every field the way the scene
// and lens-profile readers do and throws BoardError("FILE: FIELD: REASON").
//
// Plain data only: pipeline/config/lens_sources.h turns a LensSourceConfig into a
// hal::lens::LensEncoder.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <glm/vec3.hpp>

#include "camhead/base/config_error.h"
#include "camhead/base/video_format.h"
#include "camhead/renderer/accumulation.h"
#include "web/web_access.h"

namespace camhead::pipeline {

// A board file that cannot be used (base/config_error.h).
class BoardError : public base::ConfigError {
public:
  using base::ConfigError::ConfigError;
  explicit BoardError(const base::ConfigError &e) : base::ConfigError(e) {}
};

// A recorded lens trace played back in real time (the simulated rig).
struct TraceSourceConfig {
  std::filesystem::path file;
  bool loop = true;
  double speed = 1.0;
  // The trace's time 0 at CLOCK_MONOTONIC 0 ("clock_origin": "monotonic"),
  // so that the simulated camera films the lens the trace plays, and tests
  // know the lens at any instant; else it starts when the rig starts.
  bool monotonic_origin = false;
};

// The camhead USB lens-encoder board (docs/usb-lens-protocol.md).
struct UsbSourceConfig {
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::optional<std::string> serial;
  // Run the simulated board instead, its encoders following this trace.
  std::optional<std::filesystem::path> simulate;
};

// Quadrature encoders on GPIO lines of one chip.
struct GpioAxisConfig {
  unsigned line_a = 0, line_b = 0;
  std::optional<unsigned> line_index;
  bool index_active_low = false;
  std::optional<std::int32_t> counts_at_index; // homes the axis on the index pulse
  bool reverse = false;
};
enum class GpioBias { as_is, disable, pull_up, pull_down };
struct GpioSourceConfig {
  std::string chip; // "gpiochip0", "/dev/gpiochip0" or a chip label
  std::optional<GpioAxisConfig> focus, iris, zoom;
  GpioBias bias = GpioBias::as_is;
  // Run the simulated chip instead, its encoders following this trace.
  std::optional<std::filesystem::path> simulate;
};

// FreeD D1 over UDP.
struct FreedSourceConfig {
  std::string bind_address = "0.0.0.0";
  std::uint16_t port = 40000;
  std::optional<std::uint8_t> camera_id;
};

// OpenTrackIO over UDP.
struct OpenTrackIoSourceConfig {
  std::string bind_address = "0.0.0.0";
  std::uint16_t port = 55555;
  std::optional<std::string> multicast_group;
};

using LensSourceKind = std::variant<TraceSourceConfig, UsbSourceConfig, GpioSourceConfig,
                                    FreedSourceConfig, OpenTrackIoSourceConfig>;

struct LensSourceConfig {
  std::string name; // for messages and the monitor; defaults to the type
  LensSourceKind kind;
  // How much later than the physical instant this source stamps its samples
  // (lens_control's per-source delay). Broadcast tracking users set it.
  double delay_ms = 0.0;
};

struct LensConfig {
  // Empty: the uncalibrated fallback profile, flagged as such.
  std::optional<std::filesystem::path> profile;
  std::vector<LensSourceConfig> sources;
};

// The simulated camera (hal/camera/sim): the board's scene's real objects
// rendered through the board's lens at each exposure.
struct SimCameraConfig {
  double fps = 25.0;
  std::uint32_t samples = 2; // rays per pixel of the simulated world
  // Memory for pictures already rendered, MiB; 0 renders every frame.
  std::uint32_t cache_mb = 256;
  // Fault option: the camera goes away after this many frames, for
  // disconnect_s, and comes back; silently: it only stops sending.
  std::optional<std::uint64_t> disconnect_after_frames;
  double disconnect_s = 1.0;
  bool disconnect_silently = false;
  // A camera path (pipeline/tracking/pose_trace.h) the camera moves along;
  // else it stands at the board's pose.
  std::optional<std::filesystem::path> path;
  // false: every frame rendered and taken, stamped 1 / fps apart, however
  // long each takes (a reproducible run, as a file camera's offline take).
  bool realtime = true;
};

// A Y4M video or PNG sequence played as the camera (hal/camera/file).
struct FileCameraConfig {
  std::filesystem::path path;
  bool loop = true;
  bool realtime = true; // false: as fast as frames are taken
};

// A V4L2 capture device (hal/camera/v4l2): a USB webcam, an HDMI capture
// card, a CSI sensor's video node.
struct V4l2CameraConfig {
  std::string device; // /dev/videoN or a /dev/v4l/by-id/... name
  double fps = 0.0;   // 0: the driver's rate
  int buffers = 4;
  bool mjpeg = false; // "format": "mjpeg": decoded to rgb24 as it arrives
};

// A camera through libcamera (hal/camera/libcamera): CSI sensors behind an
// ISP (Raspberry Pi, Rockchip), or any camera libcamera supports.
struct LibcameraCameraConfig {
  std::string camera_id; // libcamera's id; empty: the first camera
  int buffers = 4;
};

using CameraKind =
    std::variant<SimCameraConfig, FileCameraConfig, V4l2CameraConfig, LibcameraCameraConfig>;

struct CameraConfig {
  CameraKind kind;
  base::PixelFormat format = base::PixelFormat::yuyv;
  int width = 720;
  int height = 576;
  double sensor_width_mm = 36.0; // the width the lens projects onto
};

// Where the camera is. `fixed` ("static" in the file): the position, look-at
// point and up direction given, or the scene file's camera when the board
// has no pose. `freed` and `opentrackio`: the pose a tracker sends in the
// datagrams of one of the board's lens sources of that type (one socket
// carries both), moved back by `delay_ms`; the scene's camera until the
// first pose arrives (pipeline/tracking/tracker_axes.h: the axes).
// `marker`: found in each frame's own picture from a marker board
// (pipeline/tracking/marker_board.h), with that frame's lens. `trace`: a
// camera path (pipeline/tracking/pose_trace.h) at each frame's mid-exposure,
// a perfect tracker (the simulated camera's own path is its truth).
enum class PoseType { fixed, freed, opentrackio, marker, trace };

struct PoseConfig {
  PoseType type = PoseType::fixed;
  std::array<double, 3> position{0.0, 0.0, 0.0};
  std::array<double, 3> look_at{0.0, 0.0, -1.0};
  std::array<double, 3> up{0.0, 1.0, 0.0};
  // A tracker's: the name of the lens source whose datagrams carry the pose,
  // and how much later than the physical instant its poses are stamped.
  std::string source;
  double delay_ms = 0.0;
  // A marker pose's marker-board file ("board"); a trace pose's camera path
  // ("file").
  std::filesystem::path file;
};

// Whether the pose comes in a lens source's datagrams (freed, opentrackio).
[[nodiscard]] inline bool pose_from_lens_source(PoseType type) {
  return type == PoseType::freed || type == PoseType::opentrackio;
}

// "static", "freed", "opentrackio", "marker", "trace", as board files spell
// the type.
[[nodiscard]] std::string_view pose_type_name(PoseType type);

// The pose as the renderer takes it: float32, `up` made of unit length
// first (in double, so that a tiny one keeps its direction). The board
// reader refuses a pose whose vectors give the renderer no view
// (renderer/frame_camera.h).
struct PoseVectors {
  glm::vec3 position, look_at, up;
};
[[nodiscard]] PoseVectors pose_vectors(const PoseConfig &pose);

enum class Executor { automatic, cpu, gpu };

struct RenderConfig {
  Executor executor = Executor::automatic;
  // Rays per pixel: chosen per frame within [min, max] to keep the camera's
  // rate (FrameBudget), or fixed.
  std::uint32_t min_rays_per_pixel = 1;
  std::uint32_t max_rays_per_pixel = 64;
  std::optional<std::uint32_t> rays_per_pixel;
  bool adaptive = false;
  // How each frame adds to the frames before while the lens and pose hold
  // still (renderer/accumulation.h): on unless `adaptive`.
  renderer::AccumulationSettings accumulation{.enabled = true};
};

struct Board {
  std::string name;
  std::string description;
  std::filesystem::path file; // where it was loaded from
  // The file as it was read: a reload compares with it what only a restart
  // may change (run/board_reload.h).
  std::string text;
  LensConfig lens;
  // The live pipeline (`camhead run`); a board without a camera serves only
  // the lens commands.
  std::optional<CameraConfig> camera;
  std::optional<std::filesystem::path> scene; // virtual objects and the real proxy
  std::optional<PoseConfig> pose;
  std::vector<std::string> outputs; // output URIs, as `camhead run --output`
  RenderConfig render;
  // The operator page (`camhead run --http`): where it listens and its
  // password file; none: off unless the command line asks.
  std::optional<web::WebOptions> http;
};

// "sim" and the other names in board/ resolve to board/<name>.json in the
// data folder (data_dir.h); anything with a '/' or a '.' is a path. Throws
// BoardError when a name is given and no data folder is found, or when its
// board/ has no such name (the error lists the names it has).
[[nodiscard]] std::filesystem::path resolve_board(std::string_view name_or_path);

// Loads and validates a board file. Throws BoardError.
[[nodiscard]] Board load_board(const std::filesystem::path &file);
// Parses board JSON text; `file` names it in errors and anchors relative
// paths. Throws BoardError.
[[nodiscard]] Board parse_board(std::string_view json_text, const std::filesystem::path &file);

// "trace", "usb", ... as board files spell the type.
[[nodiscard]] std::string_view source_type(const LensSourceConfig &source);

} // namespace camhead::pipeline
