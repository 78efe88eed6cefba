// FreeD D1 receiver over real sockets on 127.0.0.1: readings, timestamps,
// malformed counting, the camera-id filter, the timeout, socket errors.
#include <array>
#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "camhead/hal/lens/network/freed.h"
#include "camhead/hal/lens/network/freed_receiver.h"
#include "udp_test_support.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

using std::chrono::milliseconds;

FreedReceiverConfig loopback(std::optional<std::uint8_t> camera = std::nullopt) {
  FreedReceiverConfig c;
  c.bind_address = "127.0.0.1";
  c.port = 0;
  c.camera_id = camera;
  return c;
}

std::array<std::uint8_t, kFreedD1Size> d1(std::uint32_t focus, std::uint32_t zoom,
                                          std::uint8_t camera = 1) {
  FreedD1 m;
  m.camera_id = camera;
  m.focus = focus;
  m.zoom = zoom;
  m.pan_deg = 12.5;
  return encode_freed_d1(m);
}

TEST(FreedReceiver, EphemeralPortIsReportedAndNamed) {
  FreedReceiver rx(loopback());
  EXPECT_NE(rx.port(), 0);
  EXPECT_EQ(rx.name(), "freed udp 127.0.0.1:" + std::to_string(rx.port()));
  EXPECT_FALSE(rx.status().connected);
  EXPECT_NE(rx.status().detail.find("waiting"), std::string::npos) << rx.status().detail;
}

TEST(FreedReceiver, DeliversCountsStampedAtReceipt) {
  FreedReceiver rx(loopback());
  test::RawSender tx(rx.port());
  const std::int64_t before = test::now_ns();
  ASSERT_TRUE(tx.send(d1(100, 0xFFFFFF)));
  ASSERT_TRUE(tx.send(d1(200, 7)));
  ASSERT_TRUE(tx.send(d1(0x123456, 8)));
  const std::vector<EncoderReading> got = test::collect(rx, 3);
  const std::int64_t after = test::now_ns();

  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(got[0].focus, 100);
  EXPECT_EQ(got[0].zoom, 0xFFFFFF);
  EXPECT_EQ(got[2].focus, 0x123456);
  EXPECT_EQ(got[2].zoom, 8);
  std::int64_t previous = before;
  for (const EncoderReading &r : got) {
    EXPECT_FALSE(r.iris) << "FreeD D1 has no iris field";
    EXPECT_FALSE(r.focus_distance_m || r.f_stop || r.focal_length_mm);
    EXPECT_GE(r.t_ns, previous) << "stamps run forwards, from no earlier than the first send";
    EXPECT_LE(r.t_ns, after);
    previous = r.t_ns;
  }
  const EncoderStatus s = rx.status();
  EXPECT_TRUE(s.connected);
  EXPECT_EQ(s.readings, 3u);
  EXPECT_EQ(s.malformed, 0u);
  EXPECT_NE(s.detail.find("receiving from 127.0.0.1:"), std::string::npos) << s.detail;
}

TEST(FreedReceiver, DeliversThePoseInFreedsAxesAndMetres) {
  FreedReceiver rx(loopback());
  test::RawSender tx(rx.port());
  FreedD1 m;
  m.pan_deg = -45.5;
  m.tilt_deg = 10.25;
  m.roll_deg = -0.5;
  m.x_mm = 1250.0;
  m.y_mm = -3000.5;
  m.z_mm = 1600.25;
  ASSERT_TRUE(tx.send(encode_freed_d1(m)));
  const std::vector<EncoderReading> got = test::collect(rx, 1);
  ASSERT_EQ(got.size(), 1u);
  ASSERT_TRUE(got[0].pose);
  EXPECT_EQ(*got[0].pose, (TrackedPose{.x_m = 1.25,
                                       .y_m = -3.0005,
                                       .z_m = 1.60025,
                                       .pan_deg = -45.5,
                                       .tilt_deg = 10.25,
                                       .roll_deg = -0.5}));
}

TEST(FreedReceiver, MalformedDatagramsAreCountedAndDropped) {
  FreedReceiver rx(loopback());
  test::RawSender tx(rx.port());
  auto bad_checksum = d1(1, 2);
  bad_checksum[28] ^= 0xFF;
  auto wrong_type = d1(1, 2);
  wrong_type[0] = 0xD0;
  const std::vector<std::uint8_t> short_one(10, 0xD1);
  ASSERT_TRUE(tx.send(bad_checksum));
  ASSERT_TRUE(tx.send(wrong_type));
  ASSERT_TRUE(tx.send(short_one));
  ASSERT_TRUE(tx.send(d1(42, 43)));
  const std::vector<EncoderReading> got = test::collect(rx, 1);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].focus, 42);
  EXPECT_EQ(rx.status().malformed, 3u);
  EXPECT_EQ(rx.status().readings, 1u);

  // The detail names the socket, the sender and the reason.
  ASSERT_TRUE(tx.send(bad_checksum));
  std::vector<EncoderReading> none;
  const std::int64_t end = test::now_ns() + 5'000'000'000;
  while (rx.status().malformed < 4 && test::now_ns() < end) {
    rx.poll(milliseconds(20), none);
  }
  EXPECT_TRUE(none.empty());
  const EncoderStatus s = rx.status();
  EXPECT_EQ(s.malformed, 4u);
  EXPECT_NE(s.detail.find(rx.name() + ": malformed datagram from 127.0.0.1:"), std::string::npos)
      << s.detail;
  EXPECT_NE(s.detail.find("checksum"), std::string::npos) << s.detail;
}

TEST(FreedReceiver, CameraIdFilterIgnoresOtherCameras) {
  FreedReceiver rx(loopback(std::uint8_t{2}));
  test::RawSender tx(rx.port());
  ASSERT_TRUE(tx.send(d1(10, 0, 1)));
  ASSERT_TRUE(tx.send(d1(20, 0, 2)));
  ASSERT_TRUE(tx.send(d1(30, 0, 3)));
  ASSERT_TRUE(tx.send(d1(40, 0, 2)));
  const std::vector<EncoderReading> got = test::collect(rx, 2);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].focus, 20);
  EXPECT_EQ(got[1].focus, 40);
  // Camera 3 was sent before the last camera-2 message, so it has been read.
  EXPECT_EQ(rx.other_cameras(), 2u);
  EXPECT_EQ(rx.status().malformed, 0u);
}

TEST(FreedReceiver, OnlyOtherCamerasMeansNotConnected) {
  FreedReceiver rx(loopback(std::uint8_t{2}));
  test::RawSender tx(rx.port());
  ASSERT_TRUE(tx.send(d1(10, 0, 1)));
  std::vector<EncoderReading> out;
  const std::int64_t end = test::now_ns() + 5'000'000'000;
  while (rx.other_cameras() == 0 && test::now_ns() < end) {
    rx.poll(milliseconds(20), out);
  }
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(rx.other_cameras(), 1u);
  EXPECT_FALSE(rx.status().connected);
}

TEST(FreedReceiver, SilentSocketWaitsForTheTimeoutAndReturns) {
  FreedReceiver rx(loopback());
  std::vector<EncoderReading> out;
  const std::int64_t start = test::now_ns();
  rx.poll(milliseconds(50), out);
  const std::int64_t waited = test::now_ns() - start;
  EXPECT_TRUE(out.empty());
  EXPECT_GE(waited, 50'000'000) << "returned before the timeout with nothing to deliver";
  EXPECT_LT(waited, 5'000'000'000) << "did not return";

  const std::int64_t again = test::now_ns();
  rx.poll(milliseconds(0), out);
  EXPECT_LT(test::now_ns() - again, 5'000'000'000);
}

TEST(FreedReceiver, QueuedDatagramEndsTheWait) {
  FreedReceiver rx(loopback());
  test::RawSender tx(rx.port());
  ASSERT_TRUE(tx.send(d1(5, 6)));
  std::vector<EncoderReading> out;
  const std::int64_t start = test::now_ns();
  rx.poll(milliseconds(30'000), out);
  EXPECT_EQ(out.size(), 1u);
  EXPECT_LT(test::now_ns() - start, 10'000'000'000) << "waited with a reading available";
}

TEST(FreedReceiver, KernelQueueOverflowIsCountedAsLost) {
  FreedReceiver rx(loopback());
  test::RawSender tx(rx.port());
  // Far more than the default socket buffer holds while nobody reads.
  constexpr int kSent = 5000;
  for (int i = 0; i < kSent; ++i) {
    ASSERT_TRUE(tx.send(d1(static_cast<std::uint32_t>(i), 0)));
  }
  std::vector<EncoderReading> out;
  for (;;) {
    const std::size_t before = out.size();
    rx.poll(milliseconds(50), out);
    if (out.size() == before) {
      break;
    }
  }
  // Drops after the last queued datagram are reported with the next one.
  ASSERT_TRUE(tx.send(d1(kSent, 0)));
  const std::vector<EncoderReading> last = test::collect(rx, 1);
  ASSERT_EQ(last.size(), 1u);
  const EncoderStatus s = rx.status();
  EXPECT_GT(s.lost, 0u);
  EXPECT_EQ(s.readings, out.size() + 1);
  EXPECT_LE(s.readings + s.lost, std::uint64_t{kSent + 1});
  RecordProperty("freed_overflow_readings", static_cast<int>(s.readings));
  RecordProperty("freed_overflow_lost", static_cast<int>(s.lost));
}

TEST(FreedReceiver, BindConflictNamesTheSocket) {
  FreedReceiver first(loopback());
  FreedReceiverConfig same = loopback();
  same.port = first.port();
  try {
    FreedReceiver second(same);
    FAIL() << "a second unicast receiver bound the same port";
  } catch (const std::system_error &e) {
    EXPECT_EQ(std::string(e.what()), "freed udp 127.0.0.1:" + std::to_string(first.port()) +
                                         ": bind: " + std::generic_category().message(EADDRINUSE));
    EXPECT_EQ(e.code().value(), EADDRINUSE);
  }
}

TEST(FreedReceiver, AddressThatIsNotIpv4IsRejectedByName) {
  FreedReceiverConfig c = loopback();
  c.bind_address = "localhost";
  try {
    FreedReceiver rx(c);
    FAIL() << "accepted a host name as bind address";
  } catch (const std::invalid_argument &e) {
    EXPECT_NE(std::string(e.what()).find("freed udp localhost:0: bind address: \"localhost\""),
              std::string::npos)
        << e.what();
  }
}

} // namespace
} // namespace camhead::hal::lens
