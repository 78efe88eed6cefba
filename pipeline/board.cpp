// The strict board-file reader: presence, type, range and unknown fields are
// checked for every field, and the first problem is thrown as
// BoardError("FILE: FIELD: REASON"), as the scene and profile readers do.
#include "board.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "data_dir.h"

namespace camhead::pipeline {

namespace {

using Json = nlohmann::json;
using Keys = std::initializer_list<std::string_view>;

constexpr std::string_view kFormat = "camhead-board";
constexpr std::int64_t kVersion = 1;

std::string child(const std::string &field, std::string_view key) {
  return field.empty() ? std::string(key) : field + "." + std::string(key);
}

class BoardReader {
public:
  explicit BoardReader(std::filesystem::path file) : file_(std::move(file)) {}

  Board read(const Json &root) {
    keys(root, "", {"format", "version", "name", "lens"},
         {"description", "camera", "scene", "pose", "outputs", "render"});
    if (!root.at("format").is_string() || root.at("format").get<std::string>() != kFormat)
      fail("format", "must be \"" + std::string(kFormat) + "\"");
    const Json &version = root.at("version");
    if (!version.is_number_integer() || version.get<std::int64_t>() != kVersion)
      fail("version", "unsupported version (this reader understands 1)");
    Board board;
    board.file = file_;
    board.name = text(root.at("name"), "name");
    if (root.contains("description"))
      board.description = text(root.at("description"), "description", true);
    board.lens = read_lens(root.at("lens"), "lens");
    if (root.contains("camera"))
      board.camera = read_camera(root.at("camera"), "camera");
    if (root.contains("scene"))
      board.scene = path(root.at("scene"), "scene");
    if (root.contains("pose"))
      board.pose = read_pose(root.at("pose"), "pose");
    if (root.contains("outputs")) {
      const Json &outputs = root.at("outputs");
      if (!outputs.is_array())
        fail("outputs", "must be an array of output URIs (v4l2:/dev/videoN, file:PATH.y4m, ...)");
      for (std::size_t i = 0; i < outputs.size(); ++i)
        board.outputs.push_back(text(outputs[i], "outputs[" + std::to_string(i) + "]"));
    }
    if (root.contains("render"))
      board.render = read_render(root.at("render"), "render");
    if (board.camera && !board.scene)
      fail("scene", "missing: a board with a camera needs the scene of its virtual objects");
    return board;
  }

private:
  [[noreturn]] void fail(const std::string &field, const std::string &reason) const {
    throw BoardError(file_.string(), field, reason);
  }

  void keys(const Json &d, const std::string &field, Keys required, Keys optional = {}) const {
    if (!d.is_object())
      fail(field.empty() ? "(top level)" : field, "must be an object");
    for (const std::string_view k : required)
      if (!d.contains(k))
        fail(child(field, k), "missing");
    const auto listed = [](Keys ks, const std::string &k) {
      return std::find(ks.begin(), ks.end(), k) != ks.end();
    };
    for (const auto &[k, v] : d.items())
      if (!listed(required, k) && !listed(optional, k))
        fail(child(field, k), "unknown field");
  }

  std::string text(const Json &v, const std::string &field, bool may_be_empty = false) const {
    if (!v.is_string() || (!may_be_empty && v.get<std::string>().empty()))
      fail(field, may_be_empty ? "must be a string" : "must be a non-empty string");
    return v.get<std::string>();
  }

  bool flag(const Json &v, const std::string &field) const {
    if (!v.is_boolean())
      fail(field, "must be true or false");
    return v.get<bool>();
  }

  double number(const Json &v, const std::string &field, double lo, double hi) const {
    if (!v.is_number() || !std::isfinite(v.get<double>()))
      fail(field, "must be a finite number");
    const double x = v.get<double>();
    if (x < lo || x > hi) {
      std::ostringstream range;
      range << "must be within " << lo << " .. " << hi;
      fail(field, range.str());
    }
    return x;
  }

  std::int64_t integer(const Json &v, const std::string &field, std::int64_t lo,
                       std::int64_t hi) const {
    if (!v.is_number_integer() ||
        (v.is_number_unsigned() && v.get<std::uint64_t>() > std::uint64_t(hi)) ||
        v.get<std::int64_t>() < lo || v.get<std::int64_t>() > hi)
      fail(field, "must be an integer within " + std::to_string(lo) + " .. " + std::to_string(hi));
    return v.get<std::int64_t>();
  }

  // USB ids as lsusb prints them ("1209") or as integers.
  std::uint16_t usb_id(const Json &v, const std::string &field) const {
    if (v.is_string()) {
      const std::string s = v.get<std::string>();
      const bool hex = s.size() == 4 && std::all_of(s.begin(), s.end(), [](char c) {
                         return std::isxdigit(static_cast<unsigned char>(c)) != 0;
                       });
      if (!hex)
        fail(field, "must be four hexadecimal digits as lsusb prints them, e.g. \"1209\"");
      return static_cast<std::uint16_t>(std::stoul(s, nullptr, 16));
    }
    return static_cast<std::uint16_t>(integer(v, field, 0, 0xFFFF));
  }

  std::filesystem::path path(const Json &v, const std::string &field) const {
    const std::filesystem::path p = text(v, field);
    return p.is_absolute() ? p : file_.parent_path() / p;
  }

  LensConfig read_lens(const Json &d, const std::string &field) {
    keys(d, field, {"sources"}, {"profile"});
    LensConfig lens;
    if (d.contains("profile"))
      lens.profile = path(d.at("profile"), child(field, "profile"));
    const Json &sources = d.at("sources");
    const std::string sources_field = child(field, "sources");
    if (!sources.is_array() || sources.empty())
      fail(sources_field, "must be a non-empty array of lens sources");
    for (std::size_t i = 0; i < sources.size(); ++i)
      lens.sources.push_back(
          read_source(sources[i], sources_field + "[" + std::to_string(i) + "]"));
    for (std::size_t i = 0; i < lens.sources.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (lens.sources[i].name == lens.sources[j].name)
          fail(sources_field + "[" + std::to_string(i) + "].name",
               "\"" + lens.sources[i].name + "\" is already the name of sources[" +
                   std::to_string(j) + "]; give each source its own name");
    return lens;
  }

  CameraConfig read_camera(const Json &d, const std::string &field) {
    if (!d.is_object() || !d.contains("type"))
      fail(child(field, "type"), "missing (sim or file)");
    const std::string type = text(d.at("type"), child(field, "type"));
    CameraConfig camera;
    const auto with_common = [](Keys own) {
      std::vector<std::string_view> all(own);
      for (const std::string_view k : {"format", "width", "height", "sensor_width_mm"})
        all.push_back(k);
      return all;
    };
    if (type == "sim") {
      const auto optional =
          with_common({"fps", "samples", "disconnect_after_frames", "disconnect_s"});
      keys_list(d, field, {"type"}, optional);
      SimCameraConfig sim;
      if (d.contains("fps"))
        sim.fps = number(d.at("fps"), child(field, "fps"), 1.0, 240.0);
      if (d.contains("samples"))
        sim.samples = std::uint32_t(integer(d.at("samples"), child(field, "samples"), 1, 4096));
      if (d.contains("disconnect_after_frames"))
        sim.disconnect_after_frames = std::uint64_t(integer(
            d.at("disconnect_after_frames"), child(field, "disconnect_after_frames"), 0, 1 << 30));
      if (d.contains("disconnect_s"))
        sim.disconnect_s = number(d.at("disconnect_s"), child(field, "disconnect_s"), 0.0, 3600.0);
      camera.kind = sim;
    } else if (type == "file") {
      keys_list(d, field, {"type", "path"}, with_common({"loop", "realtime"}));
      FileCameraConfig file;
      file.path = path(d.at("path"), child(field, "path"));
      if (d.contains("loop"))
        file.loop = flag(d.at("loop"), child(field, "loop"));
      if (d.contains("realtime"))
        file.realtime = flag(d.at("realtime"), child(field, "realtime"));
      camera.kind = file;
    } else {
      fail(child(field, "type"), "unknown camera \"" + type + "\" (sim or file)");
    }
    if (d.contains("format")) {
      const std::string name = text(d.at("format"), child(field, "format"));
      const std::optional<base::PixelFormat> format = base::parse_pixel_format(name);
      if (!format || *format == base::PixelFormat::xrgb8888)
        fail(child(field, "format"),
             "unknown camera format \"" + name + "\" (yuyv, nv12, rgb24 or bgr24)");
      camera.format = *format;
    }
    if (d.contains("width"))
      camera.width = int(integer(d.at("width"), child(field, "width"), 2, 16384));
    if (d.contains("height"))
      camera.height = int(integer(d.at("height"), child(field, "height"), 2, 16384));
    if (camera.width % 2 != 0 || camera.height % 2 != 0)
      fail(child(field, "width"), "width and height must be even (" + std::to_string(camera.width) +
                                      "x" + std::to_string(camera.height) + ")");
    if (d.contains("sensor_width_mm"))
      camera.sensor_width_mm =
          number(d.at("sensor_width_mm"), child(field, "sensor_width_mm"), 1.0, 100.0);
    return camera;
  }

  std::array<double, 3> vec3(const Json &v, const std::string &field) const {
    if (!v.is_array() || v.size() != 3)
      fail(field, "must be an array of 3 numbers");
    std::array<double, 3> out{};
    for (std::size_t i = 0; i < 3; ++i)
      out[i] = number(v[i], field + "[" + std::to_string(i) + "]", -1e7, 1e7);
    return out;
  }

  PoseConfig read_pose(const Json &d, const std::string &field) const {
    keys(d, field, {"position", "look_at"}, {"up"});
    PoseConfig pose;
    pose.position = vec3(d.at("position"), child(field, "position"));
    pose.look_at = vec3(d.at("look_at"), child(field, "look_at"));
    if (d.contains("up"))
      pose.up = vec3(d.at("up"), child(field, "up"));
    if (pose.position == pose.look_at)
      fail(child(field, "look_at"), "must differ from position");
    return pose;
  }

  RenderConfig read_render(const Json &d, const std::string &field) const {
    keys(d, field, {},
         {"executor", "rays_per_pixel", "min_rays_per_pixel", "max_rays_per_pixel", "adaptive"});
    RenderConfig render;
    if (d.contains("executor")) {
      const std::string e = text(d.at("executor"), child(field, "executor"));
      if (e == "auto")
        render.executor = Executor::automatic;
      else if (e == "cpu")
        render.executor = Executor::cpu;
      else if (e == "gpu")
        render.executor = Executor::gpu;
      else
        fail(child(field, "executor"), "must be \"auto\", \"cpu\" or \"gpu\", not \"" + e + "\"");
    }
    const auto rpp = [&](const char *key) {
      return std::uint32_t(integer(d.at(key), child(field, key), 1, 4096));
    };
    if (d.contains("rays_per_pixel"))
      render.rays_per_pixel = rpp("rays_per_pixel");
    if (d.contains("min_rays_per_pixel"))
      render.min_rays_per_pixel = rpp("min_rays_per_pixel");
    if (d.contains("max_rays_per_pixel"))
      render.max_rays_per_pixel = rpp("max_rays_per_pixel");
    if (render.min_rays_per_pixel > render.max_rays_per_pixel)
      fail(child(field, "min_rays_per_pixel"), "must not exceed max_rays_per_pixel (" +
                                                   std::to_string(render.max_rays_per_pixel) + ")");
    if (d.contains("adaptive"))
      render.adaptive = flag(d.at("adaptive"), child(field, "adaptive"));
    return render;
  }

  void keys_list(const Json &d, const std::string &field, Keys required,
                 const std::vector<std::string_view> &optional) const {
    for (const auto &[k, v] : d.items())
      if (std::find(required.begin(), required.end(), k) == required.end() &&
          std::find(optional.begin(), optional.end(), k) == optional.end())
        fail(child(field, k), "unknown field");
    for (const std::string_view k : required)
      if (!d.contains(k))
        fail(child(field, k), "missing");
  }

  LensSourceConfig read_source(const Json &d, const std::string &field) {
    if (!d.is_object() || !d.contains("type"))
      fail(child(field, "type"), "missing (trace, usb, gpio, freed or opentrackio)");
    const std::string type = text(d.at("type"), child(field, "type"));
    LensSourceConfig source;
    if (type == "trace") {
      keys(d, field, {"type", "file"}, {"name", "delay_ms", "loop", "speed"});
      TraceSourceConfig trace;
      trace.file = path(d.at("file"), child(field, "file"));
      if (d.contains("loop"))
        trace.loop = flag(d.at("loop"), child(field, "loop"));
      if (d.contains("speed"))
        trace.speed = number(d.at("speed"), child(field, "speed"), 0.01, 100.0);
      source.kind = trace;
    } else if (type == "usb") {
      keys(d, field, {"type", "vendor_id", "product_id"},
           {"name", "delay_ms", "serial", "simulate"});
      UsbSourceConfig usb;
      usb.vendor_id = usb_id(d.at("vendor_id"), child(field, "vendor_id"));
      usb.product_id = usb_id(d.at("product_id"), child(field, "product_id"));
      if (d.contains("serial"))
        usb.serial = text(d.at("serial"), child(field, "serial"));
      if (d.contains("simulate"))
        usb.simulate = path(d.at("simulate"), child(field, "simulate"));
      source.kind = usb;
    } else if (type == "gpio") {
      keys(d, field, {"type", "chip", "axes"}, {"name", "delay_ms", "bias", "simulate"});
      source.kind = read_gpio(d, field);
    } else if (type == "freed") {
      keys(d, field, {"type"}, {"name", "delay_ms", "bind", "port", "camera_id"});
      FreedSourceConfig freed;
      read_socket(d, field, freed.bind_address, freed.port);
      if (d.contains("camera_id"))
        freed.camera_id =
            std::uint8_t(integer(d.at("camera_id"), child(field, "camera_id"), 0, 255));
      source.kind = freed;
    } else if (type == "opentrackio") {
      keys(d, field, {"type"}, {"name", "delay_ms", "bind", "port", "multicast_group"});
      OpenTrackIoSourceConfig otio;
      read_socket(d, field, otio.bind_address, otio.port);
      if (d.contains("multicast_group"))
        otio.multicast_group = text(d.at("multicast_group"), child(field, "multicast_group"));
      source.kind = otio;
    } else {
      fail(child(field, "type"),
           "unknown lens source \"" + type + "\" (trace, usb, gpio, freed or opentrackio)");
    }
    source.name = d.contains("name") ? text(d.at("name"), child(field, "name")) : type;
    if (d.contains("delay_ms"))
      source.delay_ms = number(d.at("delay_ms"), child(field, "delay_ms"), -1000.0, 1000.0);
    return source;
  }

  void read_socket(const Json &d, const std::string &field, std::string &bind,
                   std::uint16_t &port) const {
    if (d.contains("bind"))
      bind = text(d.at("bind"), child(field, "bind"));
    if (d.contains("port"))
      port = std::uint16_t(integer(d.at("port"), child(field, "port"), 1, 65535));
  }

  GpioSourceConfig read_gpio(const Json &d, const std::string &field) const {
    GpioSourceConfig gpio;
    gpio.chip = text(d.at("chip"), child(field, "chip"));
    if (d.contains("simulate"))
      gpio.simulate = path(d.at("simulate"), child(field, "simulate"));
    if (d.contains("bias")) {
      const std::string bias = text(d.at("bias"), child(field, "bias"));
      if (bias == "as_is")
        gpio.bias = GpioBias::as_is;
      else if (bias == "disable")
        gpio.bias = GpioBias::disable;
      else if (bias == "pull_up")
        gpio.bias = GpioBias::pull_up;
      else if (bias == "pull_down")
        gpio.bias = GpioBias::pull_down;
      else
        fail(child(field, "bias"), "must be as_is, disable, pull_up or pull_down");
    }
    const std::string axes_field = child(field, "axes");
    keys(d.at("axes"), axes_field, {}, {"focus", "iris", "zoom"});
    if (d.at("axes").empty())
      fail(axes_field, "must name at least one of focus, iris, zoom");
    std::vector<unsigned> used;
    const auto line = [&](const Json &v, const std::string &f) {
      const auto n = unsigned(integer(v, f, 0, 511));
      if (std::find(used.begin(), used.end(), n) != used.end())
        fail(f, "line " + std::to_string(n) + " is already used by another axis or signal");
      used.push_back(n);
      return n;
    };
    for (const auto &[axis_name, axis] : d.at("axes").items()) {
      const std::string f = child(axes_field, axis_name);
      keys(axis, f, {"a", "b"}, {"index", "index_active_low", "counts_at_index", "reverse"});
      GpioAxisConfig a;
      a.line_a = line(axis.at("a"), child(f, "a"));
      a.line_b = line(axis.at("b"), child(f, "b"));
      if (axis.contains("index"))
        a.line_index = line(axis.at("index"), child(f, "index"));
      if (axis.contains("index_active_low"))
        a.index_active_low = flag(axis.at("index_active_low"), child(f, "index_active_low"));
      if (axis.contains("counts_at_index")) {
        if (!a.line_index)
          fail(child(f, "counts_at_index"), "needs an index line");
        a.counts_at_index = std::int32_t(integer(
            axis.at("counts_at_index"), child(f, "counts_at_index"),
            std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::max()));
      }
      if (axis.contains("reverse"))
        a.reverse = flag(axis.at("reverse"), child(f, "reverse"));
      (axis_name == "focus" ? gpio.focus : axis_name == "iris" ? gpio.iris : gpio.zoom) = a;
    }
    return gpio;
  }

  std::filesystem::path file_;
};

} // namespace

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
  return dir / "board" / (s + ".json");
}

Board parse_board(std::string_view json_text, const std::filesystem::path &file) {
  Json root;
  try {
    root = Json::parse(json_text);
  } catch (const Json::parse_error &e) {
    // nlohmann's message carries the byte offset; the field is not known yet.
    throw BoardError(file.string(), "(JSON)", e.what());
  }
  return BoardReader(file).read(root);
}

Board load_board(const std::filesystem::path &file) {
  std::ifstream in(file, std::ios::binary);
  if (!in)
    throw BoardError(file.string(), "(file)", "cannot be opened");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_board(text.str(), file);
}

std::string_view source_type(const LensSourceConfig &source) {
  // In LensSourceKind's order: a new kind must add its name here.
  static constexpr std::string_view names[] = {"trace", "usb", "gpio", "freed", "opentrackio"};
  static_assert(std::size(names) == std::variant_size_v<LensSourceKind>);
  return names[source.kind.index()];
}

} // namespace camhead::pipeline
