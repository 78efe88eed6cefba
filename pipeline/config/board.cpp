// The strict board-file reader: presence, type, range and unknown fields are
// checked for every field, and the first problem is thrown as
// BoardError("FILE: FIELD: REASON"), by base's strict JSON reader
// (config_json.h), as the scene and profile readers do.
#include "config/board.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <system_error>
#include <vector>

#include <glm/geometric.hpp>

#include "camhead/base/config_json.h"
#include "camhead/base/path_text.h"
#include "camhead/renderer/frame_camera.h"
#include "config/data_dir.h"

namespace camhead::pipeline {

namespace {

using base::JsonValue;
using base::Keys;
using base::Range;

constexpr std::string_view kFormat = "camhead-board";
constexpr std::int64_t kVersion = 1;
constexpr std::int64_t kMaxCameraPixels = std::int64_t(1) << 25;

// USB ids as lsusb prints them ("1209") or as integers.
std::uint16_t usb_id(const JsonValue &v) {
  if (v.json().is_string()) {
    const std::string s = v.json().get<std::string>();
    const bool hex = s.size() == 4 && std::all_of(s.begin(), s.end(), [](char c) {
                       return std::isxdigit(static_cast<unsigned char>(c)) != 0;
                     });
    if (!hex)
      v.fail("must be four hexadecimal digits as lsusb prints them, e.g. \"1209\"");
    return static_cast<std::uint16_t>(std::stoul(s, nullptr, 16));
  }
  return static_cast<std::uint16_t>(v.integer(0, 0xFFFF));
}

// A device node or a name that stands for one (/dev/video0, gpiochip0): a
// string that names a file, so it is held to path_text.h's rule.
std::string device_name(const JsonValue &v) {
  const std::string name = v.string();
  if (const std::string problem = base::path_text_problem(name); !problem.empty())
    v.fail(problem);
  return name;
}

// One kind of a board's backends (a camera, a lens source): the name its
// "type" gives, and the reader of its object, which checks its own keys.
template <typename Variant> struct Kind {
  std::string_view type;
  Variant (*read)(const JsonValue &d);
};

// "a, b, c or d": the types a table knows, for messages.
template <typename Variant, std::size_t N> std::string type_names(const Kind<Variant> (&kinds)[N]) {
  std::string names;
  for (std::size_t i = 0; i < N; ++i)
    names += std::string(i == 0 ? "" : i + 1 == N ? " or " : ", ") + std::string(kinds[i].type);
  return names;
}

// The object `d` read by the kind its "type" names.
template <typename Variant, std::size_t N>
Variant read_kind(const JsonValue &d, const Kind<Variant> (&kinds)[N], std::string_view what) {
  const std::string names = type_names(kinds);
  const JsonValue type_value = d.at("type", names);
  const std::string type = type_value.string();
  for (const Kind<Variant> &kind : kinds)
    if (kind.type == type)
      return kind.read(d);
  type_value.fail("unknown " + std::string(what) + " \"" + type + "\" (" + names + ")");
}

std::array<double, 3> vec3(const JsonValue &v) {
  const std::vector<double> xs = v.numbers(3, Range::within(-1e7, 1e7));
  return {xs[0], xs[1], xs[2]};
}

class BoardReader {
public:
  explicit BoardReader(std::filesystem::path file) : file_(std::move(file)) {}

  Board read(const JsonValue &root) {
    root.object({"format", "version", "name", "lens"},
                {"description", "camera", "scene", "pose", "outputs", "render", "http"});
    const JsonValue format = root.at("format");
    if (!format.json().is_string() || format.json().get<std::string>() != kFormat)
      format.fail("must be \"" + std::string(kFormat) + "\"");
    const JsonValue version = root.at("version");
    if (!version.json().is_number_integer() || version.json().get<std::int64_t>() != kVersion)
      version.fail("unsupported version (this reader understands 1)");
    Board board;
    board.file = file_;
    board.name = root.at("name").string();
    if (root.has("description"))
      board.description = root.at("description").text();
    board.lens = read_lens(root.at("lens"));
    if (root.has("camera"))
      board.camera = read_camera(root.at("camera"));
    if (root.has("scene"))
      board.scene = root.at("scene").path();
    if (root.has("pose"))
      board.pose = read_pose(root.at("pose"), board.lens);
    if (root.has("outputs"))
      for (const JsonValue &output :
           root.at("outputs").elements("output URIs (v4l2:/dev/videoN, file:PATH.y4m, ...)"))
        board.outputs.push_back(output.string());
    if (root.has("render"))
      board.render = read_render(root.at("render"));
    if (root.has("http"))
      board.http = read_http(root.at("http"));
    if (board.camera && !board.scene)
      root.fail_member("scene",
                       "missing: a board with a camera needs the scene of its virtual objects");
    return board;
  }

private:
  static LensConfig read_lens(const JsonValue &d) {
    d.object({"sources"}, {"profile"});
    LensConfig lens;
    if (d.has("profile"))
      lens.profile = d.at("profile").path();
    const JsonValue sources = d.at("sources");
    if (!sources.json().is_array() || sources.json().empty())
      sources.fail("must be a non-empty array of lens sources");
    const std::vector<JsonValue> list = sources.elements();
    for (const JsonValue &source : list)
      lens.sources.push_back(read_source(source));
    for (std::size_t i = 0; i < lens.sources.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (lens.sources[i].name == lens.sources[j].name)
          list[i].fail_member("name", "\"" + lens.sources[i].name +
                                          "\" is already the name of sources[" + std::to_string(j) +
                                          "]; give each source its own name");
    return lens;
  }

  static web::WebOptions read_http(const JsonValue &d) {
    d.object({"listen"}, {"password_file", "recordings"});
    web::WebOptions http;
    const JsonValue listen = d.at("listen");
    try {
      http.listen = web::parse_listen(listen.string(), "");
    } catch (const web::WebAccessError &e) {
      listen.fail(e.what());
    }
    if (d.has("password_file"))
      http.password_file = d.at("password_file").path();
    if (d.has("recordings"))
      http.recordings = d.at("recordings").path();
    return http;
  }

  // The keys every camera takes beside its type's own.
  static Keys camera_keys(Keys own) {
    for (const std::string_view k : {"format", "width", "height", "sensor_width_mm"})
      own.push_back(k);
    return own;
  }

  static CameraKind read_sim_camera(const JsonValue &d) {
    d.object({"type"}, camera_keys({"fps", "samples", "cache_mb", "disconnect_after_frames",
                                    "disconnect_s", "disconnect_silently", "path", "realtime"}));
    SimCameraConfig sim;
    if (d.has("path"))
      sim.path = d.at("path").path();
    if (d.has("fps"))
      sim.fps = d.at("fps").number(Range::within(1.0, 240.0));
    if (d.has("samples"))
      sim.samples = std::uint32_t(d.at("samples").integer(1, 4096));
    if (d.has("cache_mb"))
      sim.cache_mb = std::uint32_t(d.at("cache_mb").integer(0, 65536));
    if (d.has("disconnect_after_frames"))
      sim.disconnect_after_frames =
          std::uint64_t(d.at("disconnect_after_frames").integer(0, 1 << 30));
    if (d.has("disconnect_s"))
      sim.disconnect_s = d.at("disconnect_s").number(Range::within(0.0, 3600.0));
    if (d.has("disconnect_silently"))
      sim.disconnect_silently = d.at("disconnect_silently").boolean();
    if (d.has("realtime"))
      sim.realtime = d.at("realtime").boolean();
    return sim;
  }

  static CameraKind read_file_camera(const JsonValue &d) {
    d.object({"type", "path"}, camera_keys({"loop", "realtime"}));
    FileCameraConfig file;
    file.path = d.at("path").path();
    if (d.has("loop"))
      file.loop = d.at("loop").boolean();
    if (d.has("realtime"))
      file.realtime = d.at("realtime").boolean();
    return file;
  }

  static CameraKind read_v4l2_camera(const JsonValue &d) {
    d.object({"type", "device"}, camera_keys({"fps", "buffers"}));
    V4l2CameraConfig v4l2;
    v4l2.device = device_name(d.at("device"));
    if (d.has("fps"))
      v4l2.fps = d.at("fps").number(Range::within(0.0, 1000.0));
    if (d.has("buffers"))
      v4l2.buffers = int(d.at("buffers").integer(2, 8));
    return v4l2;
  }

  static CameraKind read_libcamera_camera(const JsonValue &d) {
    d.object({"type"}, camera_keys({"camera_id", "buffers"}));
    LibcameraCameraConfig libcamera;
    if (d.has("camera_id"))
      libcamera.camera_id = d.at("camera_id").string();
    if (d.has("buffers"))
      libcamera.buffers = int(d.at("buffers").integer(2, 8));
    return libcamera;
  }

  static CameraConfig read_camera(const JsonValue &d) {
    static constexpr Kind<CameraKind> kCameras[] = {{"sim", read_sim_camera},
                                                    {"file", read_file_camera},
                                                    {"v4l2", read_v4l2_camera},
                                                    {"libcamera", read_libcamera_camera}};
    CameraConfig camera;
    camera.kind = read_kind(d, kCameras, "camera");
    if (const auto format = d.find("format")) {
      if (std::holds_alternative<FileCameraConfig>(camera.kind))
        format->fail("a file camera's frames are in the file's own format (Y4M 4:2:2 yuyv, "
                     "4:2:0 nv12; PNG rgb24): remove \"format\"");
      const std::string name = format->string();
      auto *v4l2 = std::get_if<V4l2CameraConfig>(&camera.kind);
      if (name == "mjpeg") {
        // Decoded on the capture thread; the frames are rgb24 from there on.
        if (v4l2 == nullptr)
          format->fail("mjpeg comes from V4L2 webcams only (type v4l2)");
        v4l2->mjpeg = true;
        camera.format = base::PixelFormat::rgb24;
      }
      const std::optional<base::PixelFormat> pixels =
          name == "mjpeg" ? camera.format : base::parse_pixel_format(name);
      if (!pixels || *pixels == base::PixelFormat::xrgb8888)
        format->fail("unknown camera format \"" + name +
                     "\" (yuyv, nv12, rgb24, bgr24, or mjpeg for a v4l2 camera)");
      camera.format = *pixels;
    }
    if (d.has("width"))
      camera.width = int(d.at("width").integer(2, 16384));
    if (d.has("height"))
      camera.height = int(d.at("height").integer(2, 16384));
    if (camera.width % 2 != 0 || camera.height % 2 != 0)
      d.fail_member("width", "width and height must be even (" + std::to_string(camera.width) +
                                 "x" + std::to_string(camera.height) + ")");
    // The image limit of every reader (docs/input-errors.md), checked here,
    // before a buffer, a renderer or an output is made for the size.
    if (std::int64_t(camera.width) * camera.height > kMaxCameraPixels)
      d.fail_member("width", std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                                 " is more than 2^25 pixels (8K UHD, 7680x4320, is within)");
    if (d.has("sensor_width_mm"))
      camera.sensor_width_mm = d.at("sensor_width_mm").number(Range::within(1.0, 100.0));
    return camera;
  }

  static PoseConfig read_pose(const JsonValue &d, const LensConfig &lens) {
    const std::string type = d.has("type") ? d.at("type").string() : "static";
    if (type == "freed" || type == "opentrackio")
      return read_tracked_pose(d, lens, type);
    if (type == "marker" || type == "trace") {
      // Found in the frame itself, or the path the camera is on: no delay
      // to correct.
      const std::string_view key = type == "marker" ? "board" : "file";
      d.object({"type", key});
      PoseConfig pose;
      pose.type = type == "marker" ? PoseType::marker : PoseType::trace;
      pose.file = d.at(key).path();
      return pose;
    }
    if (type != "static")
      d.at("type").fail("unknown pose type \"" + type +
                        "\" (static, freed, opentrackio, marker or trace)");
    d.object({"position", "look_at"}, {"type", "up"});
    PoseConfig pose;
    pose.position = vec3(d.at("position"));
    pose.look_at = vec3(d.at("look_at"));
    if (d.has("up")) {
      pose.up = vec3(d.at("up"));
      if (pose.up == std::array<double, 3>{})
        d.at("up").fail("must not be zero");
    }
    const PoseVectors v = pose_vectors(pose);
    switch (renderer::view_problem(v.position, v.look_at, v.up)) {
    case renderer::ViewProblem::none:
      break;
    case renderer::ViewProblem::no_direction:
      d.at("look_at").fail(v.position == v.look_at
                               ? "equals position (in the float32 the renderer works in)"
                               : "too close to position for the float32 the renderer works in");
    case renderer::ViewProblem::no_orientation:
      if (d.has("up"))
        d.at("up").fail("parallel to the view from position to look_at");
      // A rig looking straight down at a table, or up at a ceiling.
      d.fail_member("up", "missing, and the default [0, 1, 0] is parallel to the view from "
                          "position to look_at (straight down or up): give the direction the "
                          "top of the picture points to, e.g. [0, 0, -1]");
    }
    return pose;
  }

  // A tracker's pose: it comes in the datagrams of a lens source of the same
  // type, named by `source` or the board's only one of that type.
  static PoseConfig read_tracked_pose(const JsonValue &d, const LensConfig &lens,
                                      const std::string &type) {
    for (const char *key : {"position", "look_at", "up"})
      if (d.has(key))
        d.fail_member(key, "only a static pose has one: a " + type +
                               " pose is where its tracker says the camera is");
    d.object({"type"}, {"source", "delay_ms"});
    PoseConfig pose;
    pose.type = type == "freed" ? PoseType::freed : PoseType::opentrackio;
    const auto of_type = [&](const LensSourceConfig &s) { return source_type(s) == type; };
    if (d.has("source")) {
      pose.source = d.at("source").string();
      const auto named =
          std::find_if(lens.sources.begin(), lens.sources.end(),
                       [&](const LensSourceConfig &s) { return s.name == pose.source; });
      if (named == lens.sources.end())
        d.at("source").fail("no lens source is named \"" + pose.source +
                            "\": name one of lens.sources, of type " + type);
      if (!of_type(*named))
        d.at("source").fail("lens source \"" + pose.source + "\" is of type " +
                            std::string(source_type(*named)) + ", not " + type + ": only a " +
                            type + " source carries a " + type + " pose");
    } else {
      const auto count = std::count_if(lens.sources.begin(), lens.sources.end(), of_type);
      if (count == 0)
        d.fail_member("source", "missing, and lens.sources has no " + type +
                                    " source: add one (its socket carries the pose) and, "
                                    "if it is not the lens of the frames, list it after that one");
      if (count > 1)
        d.fail_member("source", "missing, and lens.sources has " + std::to_string(count) + " " +
                                    type + " sources: name the one that carries the pose");
      pose.source = std::find_if(lens.sources.begin(), lens.sources.end(), of_type)->name;
    }
    if (d.has("delay_ms"))
      pose.delay_ms = d.at("delay_ms").number(Range::within(-1000.0, 1000.0));
    return pose;
  }

  static RenderConfig read_render(const JsonValue &d) {
    d.object({}, {"executor", "rays_per_pixel", "min_rays_per_pixel", "max_rays_per_pixel",
                  "adaptive", "accumulate", "accumulate_tolerance_px", "accumulate_max_samples",
                  "reconstruct", "reproject"});
    RenderConfig render;
    if (const auto executor = d.find("executor")) {
      const std::string e = executor->string();
      if (e == "auto")
        render.executor = Executor::automatic;
      else if (e == "cpu")
        render.executor = Executor::cpu;
      else if (e == "gpu")
        render.executor = Executor::gpu;
      else
        executor->fail("must be \"auto\", \"cpu\" or \"gpu\", not \"" + e + "\"");
    }
    const auto rpp = [&](const char *key) { return std::uint32_t(d.at(key).integer(1, 4096)); };
    if (d.has("rays_per_pixel"))
      render.rays_per_pixel = rpp("rays_per_pixel");
    if (d.has("min_rays_per_pixel"))
      render.min_rays_per_pixel = rpp("min_rays_per_pixel");
    if (d.has("max_rays_per_pixel"))
      render.max_rays_per_pixel = rpp("max_rays_per_pixel");
    if (render.min_rays_per_pixel > render.max_rays_per_pixel)
      d.fail_member("min_rays_per_pixel", "must not exceed max_rays_per_pixel (" +
                                              std::to_string(render.max_rays_per_pixel) + ")");
    if (d.has("adaptive"))
      render.adaptive = d.at("adaptive").boolean();
    // An adaptive frame shares its rays by what its own pilot saw: it keeps
    // no history, so adaptive turns accumulation off unless both are asked.
    renderer::AccumulationSettings &accumulation = render.accumulation;
    accumulation.enabled = d.has("accumulate") ? d.at("accumulate").boolean() : !render.adaptive;
    if (accumulation.enabled && render.adaptive)
      d.fail_member("accumulate", "cannot be true with \"adaptive\": true (an adaptive frame "
                                  "shares its own rays and keeps no history); choose one");
    if (d.has("accumulate_tolerance_px"))
      accumulation.tolerance_px = d.at("accumulate_tolerance_px").number(Range::within(0.0, 100.0));
    if (d.has("accumulate_max_samples"))
      accumulation.max_samples = rpp("accumulate_max_samples");
    if (d.has("reconstruct"))
      accumulation.reconstruct = d.at("reconstruct").boolean();
    if (d.has("reproject"))
      accumulation.reproject = d.at("reproject").boolean();
    return render;
  }

  static LensSourceKind read_trace_source(const JsonValue &d) {
    d.object({"type", "file"}, {"name", "delay_ms", "loop", "speed", "clock_origin"});
    TraceSourceConfig trace;
    trace.file = d.at("file").path();
    if (const auto clock_origin = d.find("clock_origin")) {
      const std::string origin = clock_origin->string();
      if (origin != "start" && origin != "monotonic")
        clock_origin->fail("must be \"start\" or \"monotonic\", not \"" + origin + "\"");
      trace.monotonic_origin = origin == "monotonic";
    }
    if (d.has("loop"))
      trace.loop = d.at("loop").boolean();
    if (d.has("speed"))
      trace.speed = d.at("speed").number(Range::within(0.01, 100.0));
    // Time 0 at the machine's boot, played once: over before any run
    // starts, and every frame would get the profile's rest state.
    if (trace.monotonic_origin && !trace.loop)
      d.fail_member("loop", "false with clock_origin \"monotonic\": the trace would start at "
                            "the machine's boot and be over before the run; loop it, or use "
                            "clock_origin \"start\"");
    return trace;
  }

  static LensSourceKind read_usb_source(const JsonValue &d) {
    d.object({"type", "vendor_id", "product_id"}, {"name", "delay_ms", "serial", "simulate"});
    UsbSourceConfig usb;
    usb.vendor_id = usb_id(d.at("vendor_id"));
    usb.product_id = usb_id(d.at("product_id"));
    if (d.has("serial"))
      usb.serial = d.at("serial").string();
    if (d.has("simulate"))
      usb.simulate = d.at("simulate").path();
    return usb;
  }

  static LensSourceKind read_gpio_source(const JsonValue &d) {
    d.object({"type", "chip", "axes"}, {"name", "delay_ms", "bias", "simulate"});
    return read_gpio(d);
  }

  static LensSourceKind read_freed_source(const JsonValue &d) {
    d.object({"type"}, {"name", "delay_ms", "bind", "port", "camera_id"});
    FreedSourceConfig freed;
    read_socket(d, freed.bind_address, freed.port);
    if (d.has("camera_id"))
      freed.camera_id = std::uint8_t(d.at("camera_id").integer(0, 255));
    return freed;
  }

  static LensSourceKind read_opentrackio_source(const JsonValue &d) {
    d.object({"type"}, {"name", "delay_ms", "bind", "port", "multicast_group"});
    OpenTrackIoSourceConfig otio;
    read_socket(d, otio.bind_address, otio.port);
    if (d.has("multicast_group"))
      otio.multicast_group = d.at("multicast_group").string();
    return otio;
  }

  static LensSourceConfig read_source(const JsonValue &d) {
    static constexpr Kind<LensSourceKind> kSources[] = {{"trace", read_trace_source},
                                                        {"usb", read_usb_source},
                                                        {"gpio", read_gpio_source},
                                                        {"freed", read_freed_source},
                                                        {"opentrackio", read_opentrackio_source}};
    LensSourceConfig source;
    source.kind = read_kind(d, kSources, "lens source");
    source.name = d.has("name") ? d.at("name").string() : d.at("type").string();
    if (d.has("delay_ms"))
      source.delay_ms = d.at("delay_ms").number(Range::within(-1000.0, 1000.0));
    return source;
  }

  static void read_socket(const JsonValue &d, std::string &bind, std::uint16_t &port) {
    if (d.has("bind"))
      bind = d.at("bind").string();
    if (d.has("port"))
      port = std::uint16_t(d.at("port").integer(1, 65535));
  }

  static GpioSourceConfig read_gpio(const JsonValue &d) {
    GpioSourceConfig gpio;
    gpio.chip = device_name(d.at("chip"));
    if (d.has("simulate"))
      gpio.simulate = d.at("simulate").path();
    if (const auto bias_value = d.find("bias")) {
      const std::string bias = bias_value->string();
      if (bias == "as_is")
        gpio.bias = GpioBias::as_is;
      else if (bias == "disable")
        gpio.bias = GpioBias::disable;
      else if (bias == "pull_up")
        gpio.bias = GpioBias::pull_up;
      else if (bias == "pull_down")
        gpio.bias = GpioBias::pull_down;
      else
        bias_value->fail("must be as_is, disable, pull_up or pull_down");
    }
    const JsonValue axes = d.at("axes");
    axes.object({}, {"focus", "iris", "zoom"});
    if (axes.json().empty())
      axes.fail("must name at least one of focus, iris, zoom");
    std::vector<unsigned> used;
    const auto line = [&](const JsonValue &v) {
      const auto n = unsigned(v.integer(0, 511));
      if (std::find(used.begin(), used.end(), n) != used.end())
        v.fail("line " + std::to_string(n) + " is already used by another axis or signal");
      used.push_back(n);
      return n;
    };
    for (const auto &[axis_name, axis] : axes.members()) {
      axis.object({"a", "b"}, {"index", "index_active_low", "counts_at_index", "reverse"});
      GpioAxisConfig a;
      a.line_a = line(axis.at("a"));
      a.line_b = line(axis.at("b"));
      if (axis.has("index"))
        a.line_index = line(axis.at("index"));
      if (axis.has("index_active_low"))
        a.index_active_low = axis.at("index_active_low").boolean();
      if (const auto counts = axis.find("counts_at_index")) {
        if (!a.line_index)
          counts->fail("needs an index line");
        a.counts_at_index = std::int32_t(counts->integer(std::numeric_limits<std::int32_t>::min(),
                                                         std::numeric_limits<std::int32_t>::max()));
      }
      if (axis.has("reverse"))
        a.reverse = axis.at("reverse").boolean();
      (axis_name == "focus" ? gpio.focus : axis_name == "iris" ? gpio.iris : gpio.zoom) = a;
    }
    return gpio;
  }

  std::filesystem::path file_;
};

} // namespace

std::string_view pose_type_name(PoseType type) {
  switch (type) {
  case PoseType::fixed:
    return "static";
  case PoseType::freed:
    return "freed";
  case PoseType::opentrackio:
    return "opentrackio";
  case PoseType::marker:
    return "marker";
  case PoseType::trace:
    return "trace";
  }
  return "static";
}

PoseVectors pose_vectors(const PoseConfig &pose) {
  const auto f = [](const std::array<double, 3> &a) {
    return glm::vec3(float(a[0]), float(a[1]), float(a[2]));
  };
  // Scaled by its largest component first, so that a tiny `up` (1e-300)
  // does not underflow to zero when squared.
  glm::dvec3 up(pose.up[0], pose.up[1], pose.up[2]);
  const double largest = std::max({std::abs(up.x), std::abs(up.y), std::abs(up.z)});
  if (largest > 0.0)
    up /= largest;
  const double length = glm::length(up);
  return {f(pose.position), f(pose.look_at),
          length > 0.0 ? glm::vec3(up / length) : glm::vec3(0.0f)};
}

std::filesystem::path resolve_board(std::string_view name_or_path) {
  const std::string s(name_or_path);
  const bool bare_name = s.find('/') == std::string::npos && s.find('.') == std::string::npos;
  if (!bare_name)
    return s;
  const std::filesystem::path dir = data_dir();
  if (dir.empty())
    throw BoardError(s, "(board name)",
                     "no camhead data folder found (one holding board/sim.json); searched:\n" +
                         describe_data_dir_search() +
                         "set CAMHEAD_DATA_DIR, or give the board file's path");
  std::error_code error;
  // The administrator's boards first (conffiles of the package).
  const std::filesystem::path config = config_board_dir();
  if (!config.empty() && std::filesystem::exists(config / (s + ".json"), error))
    return config / (s + ".json");
  const std::filesystem::path folder = dir / "board", file = folder / (s + ".json");
  if (std::filesystem::exists(file, error) || !std::filesystem::is_directory(folder, error))
    return file; // found; or load_board names the file it cannot open
  // A misspelt name: say which names there are.
  std::vector<std::string> names;
  for (const std::filesystem::path &where : {config, folder})
    for (const auto &entry : std::filesystem::directory_iterator(where, error))
      if (entry.path().extension() == ".json")
        names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  std::string known;
  for (const std::string &name : names)
    known += (known.empty() ? "" : ", ") + name;
  throw BoardError(
      s, "(board name)",
      "no board of that name in " +
          (config.empty() ? folder.string() : config.string() + " or " + folder.string()) +
          " (there: " + known + "); give a board file's path for your own");
}

Board parse_board(std::string_view json_text, const std::filesystem::path &file) {
  try {
    const std::filesystem::path folder = board_paths_folder(file);
    const base::JsonFile json = folder.empty() ? base::JsonFile(json_text, file.string())
                                               : base::JsonFile(json_text, file.string(), folder);
    Board board = BoardReader(file).read(json.root());
    board.text = json_text;
    return board;
  } catch (const base::ConfigError &e) {
    throw BoardError(e);
  }
}

Board load_board(const std::filesystem::path &file) {
  std::string text;
  try {
    text = base::read_config_file(file);
  } catch (const base::ConfigError &e) {
    throw BoardError(e);
  }
  return parse_board(text, file);
}

std::string_view source_type(const LensSourceConfig &source) {
  // In LensSourceKind's order: a new kind must add its name here.
  static constexpr std::string_view names[] = {"trace", "usb", "gpio", "freed", "opentrackio"};
  static_assert(std::size(names) == std::variant_size_v<LensSourceKind>);
  return names[source.kind.index()];
}

} // namespace camhead::pipeline
