// Gaps in libcamera's buffer sequence numbers are drops
// (hal/camera/libcamera/src/sequence_gaps.h).
#include "sequence_gaps.h"

#include <gtest/gtest.h>

namespace camhead::hal::camera::libcamera_settings {
namespace {

TEST(LibcameraSequenceGaps, GapsAreDropsAndNumbersGoOn) {
  SequenceGaps gaps;
  EXPECT_EQ(gaps.next(10).sequence, 0u);
  EXPECT_EQ(gaps.next(11).dropped, 0u);
  const SequenceGaps::Step step = gaps.next(14);
  EXPECT_EQ(step.dropped, 2u);
  EXPECT_EQ(step.sequence, 4u);
}

TEST(LibcameraSequenceGaps, WrapRepeatAndRestartAreNotDrops) {
  SequenceGaps gaps;
  (void)gaps.next(0xffff'ffffu);
  EXPECT_EQ(gaps.next(0).dropped, 0u);
  EXPECT_EQ(gaps.next(0).dropped, 0u); // repeated
  gaps.restart();
  const SequenceGaps::Step step = gaps.next(0x1234);
  EXPECT_EQ(step.dropped, 0u);
  EXPECT_EQ(step.sequence, 3u);
}

} // namespace
} // namespace camhead::hal::camera::libcamera_settings
