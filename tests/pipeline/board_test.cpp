// Board files: the bundled ones load, and every kind of mistake is named by
// file and field without loading anything half-way.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "config/board.h"
#include "config/data_dir.h"
#include "run/output_uri.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

const std::filesystem::path kBoards = std::filesystem::path(CAMHEAD_SOURCE_DIR) / "board";

std::string error_of(const std::string &json) {
  try {
    static_cast<void>(parse_board(json, "/rigs/test.json"));
  } catch (const BoardError &e) {
    return e.what();
  }
  return "(no error)";
}

std::string with_source(const std::string &source) {
  return R"({"format": "camhead-board", "version": 1, "name": "t",
             "lens": {"sources": [)" +
         source + "]}}";
}

// An administrator's boards (the package's conffiles in /etc/camhead/board;
// CAMHEAD_CONFIG_DIR stands for /etc/camhead here) are found by name before
// the shipped ones, and an edited copy of a shipped board finds the scenes
// and lens files the shipped one does.
TEST(Board, AnAdministratorsBoardIsFoundFirstAndReadsPathsAsTheShippedOne) {
  namespace fs = std::filesystem;
  const fs::path config = fs::temp_directory_path() / "camhead_config_dir_test";
  fs::remove_all(config);
  fs::create_directories(config / "board");
  std::stringstream shipped;
  shipped << std::ifstream(kBoards / "sim.json").rdbuf();
  std::string edited = shipped.str();
  edited.replace(edited.find("\"name\": \"sim\""), 13, "\"name\": \"ours\"");
  std::ofstream(config / "board" / "sim.json") << edited;
  std::ofstream(config / "board" / "mine.json") << edited;
  ::setenv("CAMHEAD_CONFIG_DIR", config.c_str(), 1);

  EXPECT_EQ(resolve_board("sim"), config / "board" / "sim.json");
  EXPECT_EQ(resolve_board("mine"), config / "board" / "mine.json");
  EXPECT_EQ(resolve_board("sim-moving"), data_dir() / "board" / "sim-moving.json")
      << "a board the administrator has no copy of is the shipped one";
  const Board board = load_board(resolve_board("sim"));
  EXPECT_EQ(board.name, "ours");
  ASSERT_TRUE(board.lens.profile.has_value());
  EXPECT_EQ(*board.lens.profile,
            (data_dir() / "scenes/lenses/example_35mm.json").lexically_normal());
  EXPECT_TRUE(fs::exists(*board.scene)) << *board.scene;
  try {
    (void)resolve_board("sin");
    ADD_FAILURE() << "a misspelt name was taken";
  } catch (const BoardError &e) {
    const std::string what = e.what();
    EXPECT_NE(what.find((config / "board").string() + " or "), std::string::npos) << what;
    EXPECT_NE(what.find("mine, "), std::string::npos) << what;
    EXPECT_NE(what.find("sim-moving"), std::string::npos) << what;
  }
  ::unsetenv("CAMHEAD_CONFIG_DIR");
  fs::remove_all(config);
  EXPECT_EQ(resolve_board("sim"), data_dir() / "board" / "sim.json")
      << "a camhead in its build tree sees its own boards alone";
}

TEST(Board, SimulatedRigLoadsWithATraceAndAProfileThatExist) {
  const Board board = load_board(resolve_board("sim"));
  EXPECT_EQ(board.name, "sim");
  ASSERT_EQ(board.lens.sources.size(), 1u);
  const auto *trace = std::get_if<TraceSourceConfig>(&board.lens.sources[0].kind);
  ASSERT_NE(trace, nullptr);
  EXPECT_EQ(source_type(board.lens.sources[0]), "trace");
  EXPECT_TRUE(trace->loop);
  EXPECT_TRUE(std::filesystem::exists(trace->file)) << trace->file;
  ASSERT_TRUE(board.lens.profile.has_value());
  EXPECT_TRUE(std::filesystem::exists(*board.lens.profile)) << *board.lens.profile;
}

// The two real boards beside the simulated rig load whole: their files
// exist, their camera and outputs are what their descriptions promise, and
// their output URIs parse (nothing is opened: there is no Pi here).
TEST(Board, TheRealBoardsLoadWithTheirCamerasAndOutputs) {
  const Board pi = load_board(resolve_board("rpi5-libcamera-hdmi"));
  ASSERT_TRUE(pi.camera.has_value());
  EXPECT_NE(std::get_if<LibcameraCameraConfig>(&pi.camera->kind), nullptr);
  EXPECT_EQ(pi.camera->format, base::PixelFormat::nv12);
  EXPECT_EQ(pi.camera->width, 1920);
  EXPECT_EQ(pi.camera->height, 1080);
  ASSERT_EQ(pi.outputs, std::vector<std::string>{"drm:card1:HDMI-A-1"});
  ASSERT_EQ(pi.lens.sources.size(), 1u);
  EXPECT_NE(std::get_if<GpioSourceConfig>(&pi.lens.sources[0].kind), nullptr);
  ASSERT_TRUE(pi.lens.profile.has_value());
  EXPECT_TRUE(std::filesystem::exists(*pi.lens.profile)) << *pi.lens.profile;
  ASSERT_TRUE(pi.scene.has_value());
  EXPECT_TRUE(std::filesystem::exists(*pi.scene)) << *pi.scene;

  const Board pc = load_board(resolve_board("x86-uvc-webcam"));
  ASSERT_TRUE(pc.camera.has_value());
  const auto *webcam = std::get_if<V4l2CameraConfig>(&pc.camera->kind);
  ASSERT_NE(webcam, nullptr);
  EXPECT_TRUE(webcam->mjpeg);
  EXPECT_EQ(webcam->fps, 30.0);
  EXPECT_EQ(pc.camera->sensor_width_mm, 4.8);
  EXPECT_EQ(pc.outputs, std::vector<std::string>{"v4l2:/dev/video10"});
  ASSERT_EQ(pc.lens.sources.size(), 1u);
  const auto *fixed = std::get_if<TraceSourceConfig>(&pc.lens.sources[0].kind);
  ASSERT_NE(fixed, nullptr);
  EXPECT_TRUE(std::filesystem::exists(fixed->file)) << fixed->file;
  ASSERT_TRUE(pc.scene.has_value());
  EXPECT_TRUE(std::filesystem::exists(*pc.scene)) << *pc.scene;
  for (const Board *board : {&pi, &pc})
    EXPECT_NO_THROW(static_cast<void>(parse_output_uris(board->outputs))) << board->name;
}

TEST(Board, ExampleRigHasEveryKindOfSource) {
  const Board board = load_board(kBoards / "example-rig.json");
  ASSERT_EQ(board.lens.sources.size(), 4u);
  EXPECT_EQ(source_type(board.lens.sources[0]), "usb");
  EXPECT_EQ(source_type(board.lens.sources[1]), "gpio");
  EXPECT_EQ(source_type(board.lens.sources[2]), "freed");
  EXPECT_EQ(source_type(board.lens.sources[3]), "opentrackio");
  const auto &usb = std::get<UsbSourceConfig>(board.lens.sources[0].kind);
  EXPECT_EQ(usb.vendor_id, 0x1209);
  const auto &gpio = std::get<GpioSourceConfig>(board.lens.sources[1].kind);
  ASSERT_TRUE(gpio.focus && gpio.iris);
  EXPECT_FALSE(gpio.zoom);
  EXPECT_EQ(gpio.focus->line_index, 22u);
  EXPECT_TRUE(gpio.iris->reverse);
  EXPECT_DOUBLE_EQ(board.lens.sources[2].delay_ms, 16.7);
  EXPECT_EQ(std::get<FreedSourceConfig>(board.lens.sources[2].kind).camera_id, 1);
}

TEST(Board, RelativePathsAreRelativeToTheBoardFile) {
  const Board board =
      parse_board(with_source(R"({"type": "trace", "file": "traces/a.csv"})"), "/rigs/test.json");
  EXPECT_EQ(std::get<TraceSourceConfig>(board.lens.sources[0].kind).file,
            std::filesystem::path("/rigs/traces/a.csv"));
}

TEST(Board, BareNamesResolveToTheBoardFolderAndPathsStayPaths) {
  EXPECT_EQ(resolve_board("sim"), kBoards / "sim.json");
  EXPECT_EQ(resolve_board("./mine.json"), std::filesystem::path("./mine.json"));
}

TEST(Board, AnUnknownNameListsTheBoardsThereAre) {
  try {
    static_cast<void>(resolve_board("simm"));
    ADD_FAILURE() << "no error for an unknown board name";
  } catch (const BoardError &e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("simm: (board name): no board of that name in ", 0), 0u) << message;
    EXPECT_NE(message.find("(there: example-rig, rpi5-libcamera-hdmi, sim, sim-devices, "
                           "sim-moving, x86-uvc-webcam)"),
              std::string::npos)
        << message;
  }
}

TEST(Board, ErrorsNameTheFileAndTheField) {
  const std::string file = "/rigs/test.json: ";
  EXPECT_EQ(error_of("{"), file + "(JSON): " + error_of("{").substr(file.size() + 8));
  EXPECT_EQ(error_of(R"({"format": "camhead-board", "version": 2, "name": "t", "lens": {}})"),
            file + "version: unsupported version (this reader understands 1)");
  EXPECT_EQ(error_of(R"({"format": "camhead-board", "version": 1, "name": "t",
                         "lens": {"sources": []}})"),
            file + "lens.sources: must be a non-empty array of lens sources");
  EXPECT_EQ(error_of(with_source(R"({"type": "laser"})")),
            file + "lens.sources[0].type: unknown lens source \"laser\" (trace, usb, gpio, "
                   "freed or opentrackio)");
  EXPECT_EQ(error_of(with_source(R"({"type": "trace"})")), file + "lens.sources[0].file: missing");
  EXPECT_EQ(error_of(with_source(R"({"type": "trace", "file": "a.csv", "lop": true})")),
            file + "lens.sources[0].lop: unknown field");
  EXPECT_EQ(error_of(with_source(R"({"type": "usb", "vendor_id": "12x9", "product_id": 1})")),
            file + "lens.sources[0].vendor_id: must be four hexadecimal digits as lsusb prints "
                   "them, e.g. \"1209\"");
  EXPECT_EQ(error_of(with_source(R"({"type": "freed", "port": 70000})")),
            file + "lens.sources[0].port: must be an integer within 1 .. 65535");
  EXPECT_EQ(error_of(with_source(R"({"type": "gpio", "chip": "gpiochip0",
                                     "axes": {"focus": {"a": 3, "b": 3}}})")),
            file + "lens.sources[0].axes.focus.b: line 3 is already used by another axis or "
                   "signal");
  EXPECT_EQ(error_of(with_source(R"({"type": "gpio", "chip": "gpiochip0",
                                     "axes": {"focus": {"a": 1, "b": 2, "counts_at_index": 5}}})")),
            file + "lens.sources[0].axes.focus.counts_at_index: needs an index line");
  EXPECT_EQ(error_of(with_source(R"({"type": "freed"}, {"type": "freed"})")),
            file + "lens.sources[1].name: \"freed\" is already the name of sources[0]; give each "
                   "source its own name");
  EXPECT_EQ(error_of(with_source(R"({"type": "trace", "file": "a.csv", "speed": 0})")),
            file + "lens.sources[0].speed: must be within 0.01 .. 100");
}

TEST(Board, IntegersGivenAsFloatsOrHugeNumbersNameTheRange) {
  const std::string port =
      "/rigs/test.json: lens.sources[0].port: must be an integer within 1 .. 65535";
  for (const std::string &value :
       {std::string("8.0"), std::string("1e999"), std::string(400, '9'), std::string("NaN4")})
    EXPECT_EQ(error_of(with_source(R"({"type": "freed", "port": )" + value + "}")), port)
        << value.substr(0, 20);
}

TEST(Board, MissingFileIsNamed) {
  try {
    static_cast<void>(load_board("/nonexistent/rig.json"));
    FAIL() << "no error";
  } catch (const BoardError &e) {
    EXPECT_EQ(std::string(e.what()),
              "/nonexistent/rig.json: (file): cannot be opened: No such file or directory");
  }
}

} // namespace
} // namespace camhead::pipeline

namespace camhead::pipeline {
namespace {

// A board with a camera section and the live pipeline's other sections.
std::string live(const std::string &camera, const std::string &more = "") {
  return R"({"format": "camhead-board", "version": 1, "name": "t",
             "lens": {"sources": [{"type": "freed"}]}, "scene": "s.json",
             "camera": )" +
         camera + more + "}";
}

TEST(BoardLive, EveryMistakeInTheLiveSectionsIsNamed) {
  const auto expect = [](const std::string &json, const std::string &message) {
    EXPECT_EQ(error_of(json), "/rigs/test.json: " + message) << json;
  };
  expect(live(R"({"type": "usb3"})"),
         "camera.type: unknown camera \"usb3\" (sim, file, v4l2 or libcamera)");
  expect(live(R"({"type": "sim", "format": "mjpeg"})"),
         "camera.format: mjpeg comes from V4L2 webcams only (type v4l2)");
  expect(live(R"({"type": "sim", "format": "h264"})"),
         "camera.format: unknown camera format \"h264\" (yuyv, nv12, rgb24, bgr24, or mjpeg "
         "for a v4l2 camera)");
  expect(live(R"({"type": "sim", "width": 721})"),
         "camera.width: width and height must be even (721x576)");
  expect(live(R"({"type": "sim", "fps": 0})"), "camera.fps: must be within 1 .. 240");
  expect(live(R"({"type": "sim", "shutter": 180})"), "camera.shutter: unknown field");
  expect(live(R"({"type": "file"})"), "camera.path: missing");
  expect(live(R"({"type": "v4l2", "device": "/dev/video0", "buffers": 9})"),
         "camera.buffers: must be an integer within 2 .. 8");
  expect(live(R"({"type": "sim"})", R"(, "outputs": "file:x.y4m")"),
         "outputs: must be an array of output URIs (v4l2:/dev/videoN, file:PATH.y4m, ...)");
  expect(live(R"({"type": "sim"})", R"(, "render": {"executor": "tpu"})"),
         "render.executor: must be \"auto\", \"cpu\" or \"gpu\", not \"tpu\"");
  expect(live(R"({"type": "sim"})",
              R"(, "render": {"min_rays_per_pixel": 9, "max_rays_per_pixel": 4})"),
         "render.min_rays_per_pixel: must not exceed max_rays_per_pixel (4)");
  expect(live(R"({"type": "sim"})", R"(, "render": {"adaptive": true, "accumulate": true})"),
         "render.accumulate: cannot be true with \"adaptive\": true (an adaptive frame shares "
         "its own rays and keeps no history); choose one");
  expect(live(R"({"type": "sim"})", R"(, "render": {"accumulate_max_samples": 0})"),
         "render.accumulate_max_samples: must be an integer within 1 .. 4096");
  expect(live(R"({"type": "sim"})", R"(, "render": {"reproject_frames": 17})"),
         "render.reproject_frames: must be an integer within 1 .. 16");
  expect(live(R"({"type": "sim"})", R"(, "render": {"reproject_frames": 0})"),
         "render.reproject_frames: must be an integer within 1 .. 16");
  expect(live(R"({"type": "sim"})", R"(, "render": {"accumulate_tolerance_px": -1})"),
         "render.accumulate_tolerance_px: must be within 0 .. 100");
  EXPECT_EQ(
      error_of(with_source(
          R"({"type": "trace", "file": "a.csv", "clock_origin": "monotonic", "loop": false})")),
      "/rigs/test.json: lens.sources[0].loop: false with clock_origin \"monotonic\": the "
      "trace would start at the machine's boot and be over before the run; loop it, or use "
      "clock_origin \"start\"");
  expect(live(R"({"type": "sim", "width": 8192, "height": 8192})"),
         "camera.width: 8192x8192 is more than 2^25 pixels (8K UHD, 7680x4320, is within)");
  expect(live(R"({"type": "file", "path": "take.y4m", "format": "nv12"})"),
         "camera.format: a file camera's frames are in the file's own format (Y4M 4:2:2 yuyv, "
         "4:2:0 nv12; PNG rgb24): remove \"format\"");
  expect(live(R"({"type": "file", "path": "victim\u0000.y4m"})"),
         R"(camera.path: holds a NUL character (\u0000) at position 6; a file name cannot)");
  expect(live(R"({"type": "v4l2", "device": "/dev/video0\u0000x"})"),
         R"(camera.device: holds a NUL character (\u0000) at position 11; a file name cannot)");
  expect(live(R"({"type": "sim"}, "camera": {"type": "file", "path": "a.y4m"})"),
         "camera: given twice in one object; only one would count: give it once");
  // A camera without a scene has nothing to composite.
  EXPECT_EQ(error_of(R"({"format": "camhead-board", "version": 1, "name": "t",
                        "lens": {"sources": [{"type": "freed"}]}, "camera": {"type": "sim"}})"),
            "/rigs/test.json: scene: missing: a board with a camera needs the scene of its "
            "virtual objects");
}

// A live frame accumulates, reconstructs and reprojects unless the board says otherwise,
// and an adaptive one does neither (it keeps no history).
TEST(BoardLive, AccumulationIsOnUnlessAdaptive) {
  const auto render = [](const std::string &fields) {
    return parse_board(live(R"({"type": "sim"})", R"(, "render": )" + fields), "/rigs/test.json")
        .render;
  };
  EXPECT_TRUE(render("{}").accumulation.enabled);
  EXPECT_TRUE(render("{}").accumulation.reconstruct);
  EXPECT_FALSE(render(R"({"adaptive": true})").accumulation.enabled);
  EXPECT_FALSE(render(R"({"accumulate": false})").accumulation.enabled);
  EXPECT_FALSE(render(R"({"reconstruct": false})").accumulation.reconstruct);
  EXPECT_TRUE(render("{}").accumulation.reproject);
  EXPECT_FALSE(render(R"({"reproject": false})").accumulation.reproject);
  EXPECT_EQ(render("{}").accumulation.reproject_frames, 12u);
  EXPECT_EQ(render(R"({"reproject_frames": 8})").accumulation.reproject_frames, 8u);
  EXPECT_EQ(render(R"({"accumulate_max_samples": 64})").accumulation.max_samples, 64u);
  EXPECT_EQ(render(R"({"accumulate_tolerance_px": 0.2})").accumulation.tolerance_px, 0.2);
}

// A pose the tracer cannot build a view from would render no virtual object
// at all, silently: every frame the plate.
TEST(BoardLive, APoseWithoutAViewOrAnOrientationIsRefused) {
  const auto pose = [](const std::string &fields) {
    return error_of(live(R"({"type": "sim"})", R"(, "pose": {)" + fields + "}"));
  };
  const std::string file = "/rigs/test.json: ";
  EXPECT_EQ(pose(R"("position": [0, 1, 0], "look_at": [0, 1, 0])"),
            file + "pose.look_at: equals position (in the float32 the renderer works in)");
  // Different doubles, one float.
  EXPECT_EQ(pose(R"("position": [0, 1, 0], "look_at": [0, 1.00000001, 0])"),
            file + "pose.look_at: equals position (in the float32 the renderer works in)");
  // Apart in float, but too close for a direction once squared.
  EXPECT_EQ(pose(R"("position": [0, 0, 0], "look_at": [1e-30, 0, 0])"),
            file + "pose.look_at: too close to position for the float32 the renderer works in");
  // A tiny up keeps its direction (made of unit length in double).
  EXPECT_EQ(pose(R"("position": [0, 1, 0], "look_at": [0, 1, -2], "up": [0, 1e-30, 0])"),
            "(no error)");
  EXPECT_EQ(pose(R"("position": [0, 1, 0], "look_at": [0, 1, -2], "up": [1e-300, 1e-300, 0])"),
            "(no error)");
  EXPECT_EQ(pose(R"("position": [0, 1, 0], "look_at": [0, 1, -2], "up": [0, 0, 0])"),
            file + "pose.up: must not be zero");
  EXPECT_EQ(pose(R"("position": [0, 1, 0], "look_at": [0, 1, -2], "up": [0, 0, 3])"),
            file + "pose.up: parallel to the view from position to look_at");
  // A rig looking straight down at a table, with the default up.
  EXPECT_EQ(pose(R"("position": [0, 3, -2], "look_at": [0, 0, -2])"),
            file + "pose.up: missing, and the default [0, 1, 0] is parallel to the view from "
                   "position to look_at (straight down or up): give the direction the top of "
                   "the picture points to, e.g. [0, 0, -1]");
  EXPECT_EQ(pose(R"("position": [0, 3, -2], "look_at": [0, 0, -2], "up": [0, 0, -1])"),
            "(no error)");
  EXPECT_EQ(pose(R"("position": [0, 1, 0], "look_at": [0, 1, -2])"), "(no error)");
}

// A tracker's pose comes in the datagrams of one of the board's lens
// sources: the board names it, or has only one of that type.
TEST(BoardLive, ATrackersPoseNamesTheSourceThatCarriesIt) {
  const auto board = [](const std::string &sources, const std::string &pose) {
    return R"({"format": "camhead-board", "version": 1, "name": "t",
               "lens": {"sources": [)" +
           sources + R"(]}, "pose": )" + pose + "}";
  };
  const std::string usb = R"({"type": "usb", "vendor_id": "1209", "product_id": "ca3e"})";
  const std::string freed = R"({"name": "head", "type": "freed", "port": 40001})";
  const std::string otio = R"({"name": "tracker", "type": "opentrackio"})";

  const Board named = parse_board(
      board(usb + ", " + freed, R"({"type": "freed", "source": "head", "delay_ms": 33.5})"),
      "/rigs/test.json");
  ASSERT_TRUE(named.pose);
  EXPECT_EQ(named.pose->type, PoseType::freed);
  EXPECT_EQ(named.pose->source, "head");
  EXPECT_EQ(named.pose->delay_ms, 33.5);
  const Board only = parse_board(board(otio + ", " + usb, R"({"type": "opentrackio"})"), "b");
  EXPECT_EQ(only.pose->type, PoseType::opentrackio);
  EXPECT_EQ(only.pose->source, "tracker") << "the board's only opentrackio source";
  EXPECT_EQ(only.pose->delay_ms, 0.0);
  EXPECT_EQ(parse_board(board(usb, R"({"type": "static", "position": [0, 1, 0],
                                       "look_at": [0, 1, -1]})"),
                        "b")
                .pose->type,
            PoseType::fixed);

  const std::string file = "/rigs/test.json: ";
  EXPECT_EQ(error_of(board(usb, R"({"type": "markers"})")),
            file + "pose.type: unknown pose type \"markers\" (static, freed, opentrackio, "
                   "marker or trace)");
  EXPECT_EQ(error_of(board(usb, R"({"type": "marker"})")), file + "pose.board: missing");
  EXPECT_EQ(parse_board(board(usb, R"({"type": "marker", "board": "floor.json"})"), "/rigs/b.json")
                .pose->file,
            "/rigs/floor.json")
      << "relative to the board file";
  EXPECT_EQ(error_of(board(usb + ", " + freed, R"({"type": "freed", "source": "lens"})")),
            file + "pose.source: no lens source is named \"lens\": name one of lens.sources, "
                   "of type freed");
  EXPECT_EQ(error_of(board(usb + ", " + freed, R"({"type": "opentrackio", "source": "head"})")),
            file + "pose.source: lens source \"head\" is of type freed, not opentrackio: only "
                   "a opentrackio source carries a opentrackio pose");
  EXPECT_EQ(error_of(board(usb, R"({"type": "freed"})")),
            file + "pose.source: missing, and lens.sources has no freed source: add one (its "
                   "socket carries the pose) and, if it is not the lens of the frames, list it "
                   "after that one");
  EXPECT_EQ(error_of(board(freed + R"(, {"name": "b", "type": "freed", "port": 40002})",
                           R"({"type": "freed"})")),
            file + "pose.source: missing, and lens.sources has 2 freed sources: name the one "
                   "that carries the pose");
  EXPECT_EQ(error_of(board(freed, R"({"type": "freed", "position": [0, 1, 0]})")),
            file + "pose.position: only a static pose has one: a freed pose is where its "
                   "tracker says the camera is");
  EXPECT_EQ(error_of(board(freed, R"({"type": "freed", "delay_ms": 5000})")),
            file + "pose.delay_ms: must be within -1000 .. 1000");
}

// A camera path: the simulated camera moves along it, and a board's pose
// can be the same path (the simulated rig's truth).
TEST(BoardLive, ASimulatedCameraMovesAlongAPathAndAPoseCanFollowIt) {
  const Board b = parse_board(live(R"({"type": "sim", "path": "paths/dolly.csv"})",
                                   R"(, "pose": {"type": "trace", "file": "paths/dolly.csv"})"),
                              "/rigs/test.json");
  EXPECT_EQ(std::get<SimCameraConfig>(b.camera->kind).path, "/rigs/paths/dolly.csv");
  EXPECT_EQ(b.pose->type, PoseType::trace);
  EXPECT_EQ(b.pose->file, "/rigs/paths/dolly.csv");
  EXPECT_EQ(error_of(live(R"({"type": "sim"})", R"(, "pose": {"type": "trace"})")),
            "/rigs/test.json: pose.file: missing");
}

TEST(BoardLive, TheSimulatedRigHasACameraASceneAndAnOutput) {
  const Board board = load_board(resolve_board("sim"));
  ASSERT_TRUE(board.camera);
  EXPECT_TRUE(std::holds_alternative<SimCameraConfig>(board.camera->kind));
  EXPECT_EQ(board.camera->width, 720);
  EXPECT_EQ(board.camera->height, 576);
  ASSERT_TRUE(board.scene);
  EXPECT_TRUE(std::filesystem::exists(*board.scene)) << board.scene->string();
  EXPECT_EQ(board.outputs, std::vector<std::string>{"file:camhead_sim.y4m"});
}

} // namespace
} // namespace camhead::pipeline
