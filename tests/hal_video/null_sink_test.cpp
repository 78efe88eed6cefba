// The null sink counts what it is given and never fails.
#include <stdexcept>

#include "camhead/hal/output/null/null_sink.h"
#include "video_test_files.h"

#include <gtest/gtest.h>

namespace camhead {
namespace {

TEST(NullSink, CountsFramesAndNeverFails) {
  const auto format = test::make_format(base::PixelFormat::xrgb8888, 16, 9);
  auto sink = hal::output::open_null_sink(format);
  EXPECT_EQ(sink->name(), "null");
  EXPECT_EQ(sink->format(), format);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(sink->acquire().size(), base::frame_bytes(format));
    EXPECT_TRUE(sink->submit(i));
  }
  EXPECT_TRUE(sink->submit(5)); // even without acquire
  EXPECT_EQ(sink->status().frames, 6u);
  EXPECT_EQ(sink->status().errors, 0u);
  EXPECT_TRUE(sink->status().connected);
  EXPECT_TRUE(sink->close());
  EXPECT_FALSE(sink->status().connected);
}

TEST(NullSink, RefusesAFormatItCannotSize) {
  EXPECT_THROW((void)hal::output::open_null_sink(test::make_format(base::PixelFormat::nv12, 0, 2)),
               std::invalid_argument);
}

} // namespace
} // namespace camhead
