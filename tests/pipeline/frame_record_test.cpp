// The per-frame record: a lens source's or a marker board's name is the
// user's text, and goes into JSON escaped; what is not known is null.
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "run/frame_record.h"

#include <gtest/gtest.h>

namespace camhead::pipeline {
namespace {

TEST(FrameRecord, NamesAreWrittenAsJsonStrings) {
  EXPECT_EQ(json_string("freed:head"), "\"freed:head\"");
  EXPECT_EQ(json_string("marker:\"studio\" \\ B"), "\"marker:\\\"studio\\\" \\\\ B\"");
  EXPECT_EQ(json_string(std::string("a\nb\tc\x01", 6)), "\"a\\u000ab\\u0009c\\u0001\"");
  EXPECT_EQ(json_string("Kamera ü"), "\"Kamera ü\"") << "UTF-8 as it is";
}

// A composite whose pose was not found in it (its tracking not done when it
// went out): the reprojection and the tracker's time are not known, and JSON
// has no NaN. Such a frame's tracking time was written 0, as if the tracker
// had left it for a newer frame.
TEST(FrameRecord, WhatIsNotKnownIsNull) {
  char *text = nullptr;
  std::size_t size = 0;
  std::FILE *out = open_memstream(&text, &size);
  ASSERT_NE(out, nullptr);
  FrameRecord late;
  late.track_s = std::numeric_limits<double>::quiet_NaN();
  FrameRecord tracked;
  tracked.reprojection_px = 0.25;
  tracked.track_s = 0.0042;
  const RunRecordFields run{json_string("cpu"), json_string("marker:floor board")};
  write_composite_record(out, 0, late, 0, run);
  write_composite_record(out, 1, tracked, 0, run);
  std::fclose(out);
  const std::string lines(text, size);
  std::free(text);
  const std::size_t end = lines.find('\n');
  const nlohmann::json first = nlohmann::json::parse(lines.substr(0, end));
  const nlohmann::json second = nlohmann::json::parse(lines.substr(end + 1));
  EXPECT_TRUE(first["track_ms"].is_null());
  EXPECT_TRUE(first["reprojection_px"].is_null());
  EXPECT_DOUBLE_EQ(second["track_ms"].get<double>(), 4.2);
  EXPECT_DOUBLE_EQ(second["reprojection_px"].get<double>(), 0.25);
}

} // namespace
} // namespace camhead::pipeline
