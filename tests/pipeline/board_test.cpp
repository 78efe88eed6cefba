// Board files: the bundled ones load, and every kind of mistake is named by
// file and field without loading anything half-way.
#include <string>

#include "board.h"

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

TEST(Board, SimulatedRigLoadsWithATraceAndAProfileThatExist) {
  const Board board = load_board(resolve_board("sim"));
  EXPECT_EQ(board.name, "sim");
  ASSERT_EQ(board.lens.sources.size(), 1u);
  const auto *trace = std::get_if<TraceSourceConfig>(&board.lens.sources[0].kind);
  ASSERT_NE(trace, nullptr);
  EXPECT_TRUE(trace->loop);
  EXPECT_TRUE(std::filesystem::exists(trace->file)) << trace->file;
  ASSERT_TRUE(board.lens.profile.has_value());
  EXPECT_TRUE(std::filesystem::exists(*board.lens.profile)) << *board.lens.profile;
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
    EXPECT_EQ(std::string(e.what()), "/nonexistent/rig.json: (file): cannot be opened");
  }
}

} // namespace
} // namespace camhead::pipeline
