// The strict board-file reader: presence, type, range and unknown fields are
// checked for every field, and the first problem is thrown as
// BoardError("FILE: FIELD: REASON"), by base's strict JSON reader
// (config_json.h), as the scene and profile readers do.
#include "config/board.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include <glm/geometric.hpp>

#include "camhead/base/config_json.h"
#include "camhead/renderer/frame_camera.h"
#include "config/board_devices.h"
#include "config/data_dir.h"

namespace camhead::pipeline {

namespace {

using base::JsonValue;
using base::Range;

constexpr std::string_view kFormat = "camhead-board";
constexpr std::int64_t kVersion = 1;

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
      board.camera = read_camera_config(root.at("camera"));
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
      lens.sources.push_back(read_lens_source_config(source));
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
                  "reconstruct", "reproject", "reproject_frames"});
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
    if (d.has("reproject_frames"))
      accumulation.reproject_frames =
          std::uint32_t(d.at("reproject_frames")
                            .integer(1, renderer::AccumulationSettings::kMostReprojectFrames));
    return render;
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

} // namespace camhead::pipeline
