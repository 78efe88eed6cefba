// The readers of a board's devices; see board_devices.h.
#include "config/board_devices.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "camhead/base/path_text.h"

namespace camhead::pipeline {
namespace {

using base::JsonValue;
using base::Keys;
using base::Range;

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

// The keys every camera takes beside its type's own.
Keys camera_keys(Keys own) {
  for (const std::string_view k : {"format", "width", "height", "sensor_width_mm"})
    own.push_back(k);
  return own;
}

CameraKind read_sim_camera(const JsonValue &d) {
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

CameraKind read_file_camera(const JsonValue &d) {
  d.object({"type", "path"}, camera_keys({"loop", "realtime"}));
  FileCameraConfig file;
  file.path = d.at("path").path();
  if (d.has("loop"))
    file.loop = d.at("loop").boolean();
  if (d.has("realtime"))
    file.realtime = d.at("realtime").boolean();
  return file;
}

CameraKind read_v4l2_camera(const JsonValue &d) {
  d.object({"type", "device"}, camera_keys({"fps", "buffers"}));
  V4l2CameraConfig v4l2;
  v4l2.device = device_name(d.at("device"));
  if (d.has("fps"))
    v4l2.fps = d.at("fps").number(Range::within(0.0, 1000.0));
  if (d.has("buffers"))
    v4l2.buffers = int(d.at("buffers").integer(2, 8));
  return v4l2;
}

CameraKind read_libcamera_camera(const JsonValue &d) {
  d.object({"type"}, camera_keys({"camera_id", "buffers"}));
  LibcameraCameraConfig libcamera;
  if (d.has("camera_id"))
    libcamera.camera_id = d.at("camera_id").string();
  if (d.has("buffers"))
    libcamera.buffers = int(d.at("buffers").integer(2, 8));
  return libcamera;
}

void read_socket(const JsonValue &d, std::string &bind, std::uint16_t &port) {
  if (d.has("bind"))
    bind = d.at("bind").string();
  if (d.has("port"))
    port = std::uint16_t(d.at("port").integer(1, 65535));
}

GpioSourceConfig read_gpio(const JsonValue &d) {
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

LensSourceKind read_trace_source(const JsonValue &d) {
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

LensSourceKind read_usb_source(const JsonValue &d) {
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

LensSourceKind read_gpio_source(const JsonValue &d) {
  d.object({"type", "chip", "axes"}, {"name", "delay_ms", "bias", "simulate"});
  return read_gpio(d);
}

LensSourceKind read_freed_source(const JsonValue &d) {
  d.object({"type"}, {"name", "delay_ms", "bind", "port", "camera_id"});
  FreedSourceConfig freed;
  read_socket(d, freed.bind_address, freed.port);
  if (d.has("camera_id"))
    freed.camera_id = std::uint8_t(d.at("camera_id").integer(0, 255));
  return freed;
}

LensSourceKind read_opentrackio_source(const JsonValue &d) {
  d.object({"type"}, {"name", "delay_ms", "bind", "port", "multicast_group"});
  OpenTrackIoSourceConfig otio;
  read_socket(d, otio.bind_address, otio.port);
  if (d.has("multicast_group"))
    otio.multicast_group = d.at("multicast_group").string();
  return otio;
}

// In LensSourceKind's order, so that source_type() names a source by its
// index (board_test holds it).
constexpr Kind<LensSourceKind> kSources[] = {{"trace", read_trace_source},
                                             {"usb", read_usb_source},
                                             {"gpio", read_gpio_source},
                                             {"freed", read_freed_source},
                                             {"opentrackio", read_opentrackio_source}};
static_assert(std::size(kSources) == std::variant_size_v<LensSourceKind>);

} // namespace

CameraConfig read_camera_config(const JsonValue &d) {
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
    d.fail_member("width", "width and height must be even (" + std::to_string(camera.width) + "x" +
                               std::to_string(camera.height) + ")");
  // The image limit of every reader (docs/input-errors.md), checked here,
  // before a buffer, a renderer or an output is made for the size.
  if (std::int64_t(camera.width) * camera.height > kMaxCameraPixels)
    d.fail_member("width", std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                               " is more than 2^25 pixels (8K UHD, 7680x4320, is within)");
  if (d.has("sensor_width_mm"))
    camera.sensor_width_mm = d.at("sensor_width_mm").number(Range::within(1.0, 100.0));
  return camera;
}

LensSourceConfig read_lens_source_config(const JsonValue &d) {
  LensSourceConfig source;
  source.kind = read_kind(d, kSources, "lens source");
  source.name = d.has("name") ? d.at("name").string() : d.at("type").string();
  if (d.has("delay_ms"))
    source.delay_ms = d.at("delay_ms").number(Range::within(-1000.0, 1000.0));
  return source;
}

std::string_view source_type(const LensSourceConfig &source) {
  return kSources[source.kind.index()].type;
}

} // namespace camhead::pipeline
