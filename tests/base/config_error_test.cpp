// ConfigError's two message forms, reading a whole file, and the words of a
// range, which every configuration reader shares.
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "camhead/base/config_error.h"
#include "camhead/base/config_range.h"

#include <gtest/gtest.h>

namespace camhead::base {
namespace {

TEST(ConfigError, TheTwoFormsAndAWholeFileProblem) {
  const ConfigError json("lenses/x.json", "focus[3].distance_m", "must be > 0");
  EXPECT_STREQ(json.what(), "lenses/x.json: focus[3].distance_m: must be > 0");
  EXPECT_EQ(json.line(), 0);
  const ConfigError csv("marks.csv", 12, "distance_m", "must be a finite number");
  EXPECT_STREQ(csv.what(), "marks.csv:12: distance_m: must be a finite number");
  EXPECT_EQ(csv.file(), "marks.csv");
  EXPECT_EQ(csv.line(), 12);
  EXPECT_EQ(csv.field(), "distance_m");
  EXPECT_EQ(csv.reason(), "must be a finite number");
  const ConfigError whole("t.csv", 0, "", "no readings to replay");
  EXPECT_STREQ(whole.what(), "t.csv: no readings to replay");
  const std::runtime_error &base = csv; // caught as any other runtime_error
  EXPECT_STREQ(base.what(), csv.what());
}

TEST(ConfigError, ReadingAFile) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("camhead_config_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / "a.json";
  std::ofstream(file, std::ios::binary) << "{\"a\": 1}\r\n";
  EXPECT_EQ(read_config_file(file), "{\"a\": 1}\r\n");
  const auto error_of = [](const std::filesystem::path &p) {
    try {
      (void)read_config_file(p);
    } catch (const ConfigError &e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(error_of(dir), dir.string() + ": (file): is a folder, not a file");
  EXPECT_EQ(error_of(dir / "none.json"),
            (dir / "none.json").string() + ": (file): cannot be opened: No such file or directory");
  std::filesystem::remove_all(dir);
}

TEST(ConfigRange, DescribesTheAllowedValues) {
  EXPECT_EQ(Range::within(0.5, 128).describe(), "within 0.5 .. 128");
  EXPECT_EQ(Range::above(0, 1e4).describe(), "> 0 and <= 10000");
  EXPECT_EQ(Range::above(0, 1e6).describe(), "> 0 and <= 1e+06");
  EXPECT_EQ(Range::above(0).describe(), "> 0");
  EXPECT_EQ(Range::at_least(1e-9).describe(), ">= 1e-09");
  EXPECT_EQ(Range::at_most(-1).describe(), "<= -1");
  EXPECT_EQ(Range{}.describe(), "");
  EXPECT_TRUE(Range::within(0, 1).contains(0));
  EXPECT_TRUE(Range::within(0, 1).contains(1));
  EXPECT_FALSE(Range::within(0, 1).contains(1.0000001));
  EXPECT_FALSE(Range::above(0).contains(0));
  EXPECT_TRUE(Range::above(0).contains(1e-300));
  EXPECT_TRUE(Range{}.contains(-1e308));
}

} // namespace
} // namespace camhead::base
