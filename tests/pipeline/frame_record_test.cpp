// The per-frame record's shared string fields: a lens source's or a marker
// board's name is the user's text, and goes into JSON escaped.
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

} // namespace
} // namespace camhead::pipeline
