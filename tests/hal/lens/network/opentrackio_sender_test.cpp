// OpenTrackIO sender -> receiver through real sockets (unicast on 127.0.0.1,
// multicast on the loopback interface where the host allows it), and the
// sender's validation and error values.
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "camhead/hal/lens/network/opentrackio_receiver.h"
#include "camhead/hal/lens/network/opentrackio_sender.h"
#include "udp_test_support.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

OpenTrackIoSenderConfig unicast(std::string host, std::uint16_t port) {
  OpenTrackIoSenderConfig c;
  c.host = std::move(host);
  c.port = port;
  return c;
}

// A receiver on 127.0.0.1, on a port the kernel picks.
OpenTrackIoReceiverConfig loopback_receiver() {
  OpenTrackIoReceiverConfig c;
  c.bind_address = "127.0.0.1";
  c.port = 0;
  return c;
}

OpenTrackIoState state(int i) {
  OpenTrackIoState s;
  s.focus_distance_m = 0.5 + i;
  s.f_stop = 2.8;
  s.focal_length_mm = 35.0;
  s.encoder_focus = i / 10.0;
  s.encoder_iris = 0.25;
  s.encoder_zoom = 1.0;
  s.timestamp = OpenTrackIoTimestamp{1'718'000'000u + static_cast<std::uint64_t>(i), 500u};
  return s;
}

TEST(OpenTrackIoSender, RoundTripThroughRealSockets) {
  OpenTrackIoReceiver rx(loopback_receiver());
  OpenTrackIoSender tx(unicast("127.0.0.1", rx.port()));
  EXPECT_EQ(tx.name(), "opentrackio udp -> 127.0.0.1:" + std::to_string(rx.port()));

  constexpr int kCount = 8;
  for (int i = 0; i < kCount; ++i) {
    ASSERT_EQ(tx.send(state(i)), 0) << tx.last_error();
  }
  EXPECT_EQ(tx.sent(), std::uint64_t{kCount});
  EXPECT_EQ(tx.next_sequence(), kCount);

  const std::vector<EncoderReading> got = test::collect(rx, kCount);
  ASSERT_EQ(got.size(), std::size_t{kCount});
  for (int i = 0; i < kCount; ++i) {
    const EncoderReading &r = got[static_cast<std::size_t>(i)];
    EXPECT_EQ(r.focus_distance_m, 0.5 + i);
    EXPECT_EQ(r.f_stop, 2.8);
    EXPECT_EQ(r.focal_length_mm, 35.0);
    EXPECT_EQ(r.focus, std::lround(i / 10.0 * kNormalisedCounts));
    EXPECT_EQ(r.iris, std::lround(0.25 * kNormalisedCounts));
    EXPECT_EQ(r.zoom, kNormalisedCounts);
  }
  const EncoderStatus s = rx.status();
  EXPECT_EQ(s.readings, std::uint64_t{kCount});
  EXPECT_EQ(s.lost, 0u) << "the sender numbers its samples consecutively";
  EXPECT_EQ(s.malformed, 0u);
}

TEST(OpenTrackIoSender, APoseSentIsReceivedUnchanged) {
  OpenTrackIoReceiver rx(loopback_receiver());
  OpenTrackIoSender tx(unicast("127.0.0.1", rx.port()));
  // Values no decimal shorter than 17 digits carries.
  const TrackedPose camera{.x_m = 0.1 + 0.2,
                           .y_m = -2.0 / 3.0,
                           .z_m = 1.6e-7,
                           .pan_deg = 179.99999999999997,
                           .tilt_deg = -1.0 / 7.0,
                           .roll_deg = 1e-300};
  OpenTrackIoState pose_only;
  pose_only.camera = camera;
  ASSERT_EQ(tx.send(pose_only), 0) << tx.last_error();
  OpenTrackIoState with_lens = state(3);
  with_lens.camera = camera;
  ASSERT_EQ(tx.send(with_lens), 0) << tx.last_error();

  const std::vector<EncoderReading> got = test::collect(rx, 2);
  ASSERT_EQ(got.size(), 2u) << "a sample with a pose and no lens field is still a reading";
  for (const EncoderReading &r : got) {
    ASSERT_TRUE(r.pose);
    EXPECT_EQ(*r.pose, camera);
  }
  EXPECT_FALSE(got[0].focus || got[0].focus_distance_m);
  EXPECT_EQ(got[1].focus_distance_m, 3.5);
}

TEST(OpenTrackIoSender, RejectsAPoseThatIsNotFinite) {
  OpenTrackIoSender tx(unicast("127.0.0.1", 9));
  OpenTrackIoState s;
  s.camera = TrackedPose{.tilt_deg = std::numeric_limits<double>::infinity()};
  EXPECT_EQ(tx.send(s), -EINVAL);
  EXPECT_NE(tx.last_error().find("transforms[0]"), std::string::npos) << tx.last_error();
}

TEST(OpenTrackIoSender, RejectsValuesOpenTrackIoCannotCarry) {
  OpenTrackIoSender tx(unicast("127.0.0.1", 9));
  OpenTrackIoState nan_focus;
  nan_focus.focus_distance_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(tx.send(nan_focus), -EINVAL);
  EXPECT_NE(tx.last_error().find("lens.focusDistance"), std::string::npos) << tx.last_error();

  OpenTrackIoState past_end;
  past_end.encoder_iris = 1.5;
  EXPECT_EQ(tx.send(past_end), -EINVAL);
  EXPECT_NE(tx.last_error().find("lens.encoders.iris"), std::string::npos) << tx.last_error();

  EXPECT_EQ(tx.next_sequence(), 0) << "a refused sample takes no sequence number";
  EXPECT_EQ(tx.failed(), 2u);
  EXPECT_EQ(tx.sent(), 0u);
}

TEST(OpenTrackIoSender, HostThatIsNotIpv4IsRejectedByName) {
  try {
    OpenTrackIoSender tx(unicast("lens-box.local", 55555));
    FAIL() << "accepted a host name";
  } catch (const std::invalid_argument &e) {
    EXPECT_NE(std::string(e.what()).find("opentrackio udp -> lens-box.local:55555: host:"),
              std::string::npos)
        << e.what();
  }
}

// Multicast through the loopback interface: joins on 127.0.0.1 and sends out
// of it. Containers without a multicast-capable loopback skip, naming why.
TEST(OpenTrackIoSender, MulticastRoundTripOnLoopback) {
  constexpr const char *kGroup = "239.255.77.77";
  OpenTrackIoReceiverConfig rc;
  rc.port = 0;
  rc.multicast_group = kGroup;
  rc.multicast_interface = "127.0.0.1";
  std::unique_ptr<OpenTrackIoReceiver> rx;
  try {
    rx = std::make_unique<OpenTrackIoReceiver>(rc);
  } catch (const std::system_error &e) {
    GTEST_SKIP() << "cannot join a group on loopback here: " << e.what();
  }
  EXPECT_NE(rx->name().find(" group 239.255.77.77"), std::string::npos) << rx->name();
  OpenTrackIoSenderConfig sc;
  sc.host = kGroup;
  sc.port = rx->port();
  sc.multicast_interface = "127.0.0.1";
  OpenTrackIoSender tx(sc);
  const int sent = tx.send(state(3));
  if (sent == -ENETUNREACH || sent == -ENODEV) {
    GTEST_SKIP() << "no multicast route on loopback: " << tx.last_error();
  }
  ASSERT_EQ(sent, 0) << tx.last_error();
  const std::vector<EncoderReading> got = test::collect(*rx, 1);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].focus_distance_m, 3.5);
}

} // namespace
} // namespace camhead::hal::lens
