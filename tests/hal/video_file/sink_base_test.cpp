// The output state machine every backend shares (sink_base.h), driven
// through a sink whose device the test unplugs and plugs back.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "camhead/hal/output/sink_base.h"

#include <gtest/gtest.h>

namespace camhead::hal::output {
namespace {

// A device that is there or not; finish() fails while it is away.
class PlugSink final : public SinkBase {
public:
  explicit PlugSink(base::VideoFormat format) : SinkBase(format) { ready("ready"); }
  std::string name() const override { return "plug"; }

  bool plugged = true;
  int sends = 0;

private:
  bool send(std::span<const std::uint8_t>, std::int64_t) override {
    ++sends;
    if (!plugged)
      return away("unplugged; looking for it");
    return true;
  }
  bool finish() override {
    if (!plugged)
      return fail("closed while unplugged");
    return closed("closed after " + std::to_string(frames()) + " frames");
  }
};

TEST(SinkBase, CountsFramesSkipsWhileAwayAndRefusesWhatIsWrong) {
  const base::VideoFormat format{base::PixelFormat::rgb24, 4, 2};
  PlugSink sink(format);
  std::vector<std::uint8_t> frame(base::frame_bytes(format));
  EXPECT_TRUE(sink.status().connected);
  EXPECT_EQ(sink.status().detail, "plug: ready");

  EXPECT_TRUE(sink.submit(frame, 0));
  EXPECT_TRUE(sink.submit(frame, 0));
  // The wrong size never reaches the device, and is an error.
  std::vector<std::uint8_t> short_frame(frame.size() - 1);
  EXPECT_FALSE(sink.submit(short_frame, 0));
  EXPECT_EQ(sink.sends, 2);
  EXPECT_EQ(sink.status().errors, 1u);
  EXPECT_NE(sink.status().detail.find("a frame of 23 bytes, not the 24"), std::string::npos)
      << sink.status().detail;

  // Away: frames skipped, not errors; the status says why.
  sink.plugged = false;
  EXPECT_FALSE(sink.submit(frame, 0));
  EXPECT_FALSE(sink.status().connected);
  EXPECT_EQ(sink.status().detail, "plug: unplugged; looking for it");
  EXPECT_EQ(sink.status().errors, 1u);
  EXPECT_EQ(sink.status().frames, 2u);

  sink.plugged = true;
  EXPECT_TRUE(sink.submit(frame, 0));
  EXPECT_EQ(sink.status().frames, 3u);

  EXPECT_TRUE(sink.close());
  EXPECT_FALSE(sink.status().connected);
  EXPECT_EQ(sink.status().detail, "plug: closed after 3 frames");
  // After close, nothing reaches the device, and each call is an error.
  EXPECT_FALSE(sink.submit(frame, 0));
  EXPECT_FALSE(sink.close());
  EXPECT_EQ(sink.sends, 4);
  EXPECT_EQ(sink.status().errors, 3u);
  EXPECT_EQ(sink.status().detail, "plug: closed twice");
}

TEST(SinkBase, AFailedCloseIsAnErrorAndLeavesItDisconnected) {
  const base::VideoFormat format{base::PixelFormat::rgb24, 4, 2};
  PlugSink sink(format);
  sink.plugged = false;
  EXPECT_FALSE(sink.close());
  EXPECT_FALSE(sink.status().connected);
  EXPECT_EQ(sink.status().errors, 1u);
  EXPECT_EQ(sink.status().detail, "plug: closed while unplugged");
}

} // namespace
} // namespace camhead::hal::output
