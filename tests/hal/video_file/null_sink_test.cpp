// The null sink counts what it is given; it fails only a frame of the wrong
// size.
#include <stdexcept>
#include <vector>

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
  const std::vector<std::uint8_t> frame(base::frame_bytes(format));
  for (int i = 0; i < 6; ++i)
    EXPECT_TRUE(sink->submit(frame, i));
  // A frame of another size is not one of this sink's.
  EXPECT_FALSE(sink->submit(std::span(frame).first(frame.size() - 1), 6));
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
