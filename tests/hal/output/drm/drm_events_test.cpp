// Page-flip events as read() hands them over: several records in one read,
// other event types between, and damaged lengths (drm_events.h).
#include <cstring>
#include <vector>

#include <drm.h>

#include "drm_events.h"

#include <gtest/gtest.h>

namespace camhead::hal::output::drm {
namespace {

void append_flip(std::vector<std::uint8_t> &bytes, std::uint64_t user_data, std::uint32_t crtc) {
  drm_event_vblank event{};
  event.base.type = DRM_EVENT_FLIP_COMPLETE;
  event.base.length = sizeof event;
  event.user_data = user_data;
  event.crtc_id = crtc;
  const auto *raw = reinterpret_cast<const std::uint8_t *>(&event);
  bytes.insert(bytes.end(), raw, raw + sizeof event);
}

TEST(DrmEvents, SeveralRecordsInOneRead) {
  std::vector<std::uint8_t> bytes;
  append_flip(bytes, 7, 31);
  // An event type the sink did not ask for, with a body of its own length.
  drm_event other{};
  other.type = 0x80000001;
  other.length = sizeof other + 8;
  const auto *raw = reinterpret_cast<const std::uint8_t *>(&other);
  bytes.insert(bytes.end(), raw, raw + sizeof other);
  bytes.insert(bytes.end(), 8, std::uint8_t{0xee});
  append_flip(bytes, 8, 31);

  const std::vector<DrmEvent> events = parse_drm_events(bytes);
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].type, DRM_EVENT_FLIP_COMPLETE);
  EXPECT_EQ(events[0].user_data, 7u);
  EXPECT_EQ(events[0].crtc_id, 31u);
  EXPECT_EQ(events[1].type, 0x80000001u);
  EXPECT_EQ(events[1].user_data, 0u);
  EXPECT_EQ(events[2].user_data, 8u);
}

TEST(DrmEvents, DamagedLengthsStopTheParse) {
  std::vector<std::uint8_t> bytes;
  append_flip(bytes, 1, 31);
  append_flip(bytes, 2, 31);
  // The second record claims more than is there.
  std::vector<std::uint8_t> cut(bytes.begin(), bytes.end() - 4);
  EXPECT_EQ(parse_drm_events(cut).size(), 1u);
  // A zero length would loop for ever.
  drm_event zero{};
  zero.type = DRM_EVENT_FLIP_COMPLETE;
  std::vector<std::uint8_t> looping(sizeof zero);
  std::memcpy(looping.data(), &zero, sizeof zero);
  EXPECT_TRUE(parse_drm_events(looping).empty());
  EXPECT_TRUE(parse_drm_events({}).empty());
}

} // namespace
} // namespace camhead::hal::output::drm
