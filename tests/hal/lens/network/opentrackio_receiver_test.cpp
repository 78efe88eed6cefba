// OpenTrackIO receiver over real sockets on 127.0.0.1: the encoder scaling,
// calibrated fields, malformed samples, sequence loss, multicast.
#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "camhead/hal/lens/network/opentrackio.h"
#include "camhead/hal/lens/network/opentrackio_receiver.h"
#include "udp_test_support.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

using std::chrono::milliseconds;

OpenTrackIoReceiverConfig loopback() {
  OpenTrackIoReceiverConfig c;
  c.bind_address = "127.0.0.1";
  c.port = 0;
  return c;
}

std::vector<std::uint8_t> sample(std::uint16_t sequence, double focus = 0.25) {
  OpenTrackIoSample l;
  l.header_sequence = sequence;
  l.encoder_focus = focus;
  return encode_opentrackio(l);
}

std::vector<std::uint8_t> payload(std::string_view json, std::uint16_t sequence) {
  const std::vector<std::uint8_t> bytes(json.begin(), json.end());
  return encode_opentrackio_datagram(bytes, sequence);
}

// Polls until `n` datagrams of any kind were handled (readings or malformed).
void settle(OpenTrackIoReceiver &rx, std::uint64_t n, std::vector<EncoderReading> &out) {
  const std::int64_t end = test::now_ns() + 5'000'000'000;
  while (rx.status().readings + rx.status().malformed < n && test::now_ns() < end) {
    rx.poll(milliseconds(20), out);
  }
}

TEST(OpenTrackIoReading, EncodersScaleToNormalisedCounts) {
  OpenTrackIoSample l;
  l.encoder_focus = 0.0; // infinity, kept as 0
  l.encoder_iris = 1.0;
  l.encoder_zoom = 0.5;
  const auto r = reading_from_opentrackio(l, 77);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->t_ns, 77);
  EXPECT_EQ(r->focus, 0);
  EXPECT_EQ(r->iris, kNormalisedCounts);
  EXPECT_EQ(r->zoom, 32768); // 32767.5 rounds away from zero
  EXPECT_FALSE(r->focus_distance_m);
}

TEST(OpenTrackIoReading, SampleWithoutLensFieldsGivesNoReading) {
  OpenTrackIoSample l;
  l.sample_sequence = 5;
  EXPECT_FALSE(reading_from_opentrackio(l, 0));
}

TEST(OpenTrackIoReceiver, DeliversEncodersAndCalibratedFields) {
  OpenTrackIoReceiver rx(loopback());
  EXPECT_EQ(rx.name(), "opentrackio udp 127.0.0.1:" + std::to_string(rx.port()));
  test::RawSender tx(rx.port());
  const std::int64_t before = test::now_ns();
  ASSERT_TRUE(tx.send(payload(R"({"lens":{"encoders":{"focus":0,"iris":0.5,"zoom":1},
      "focusDistance":2.5,"fStop":2.8,"pinholeFocalLength":35.2}})",
                              1)));
  const std::vector<EncoderReading> got = test::collect(rx, 1);
  ASSERT_EQ(got.size(), 1u);
  const EncoderReading &r = got[0];
  EXPECT_EQ(r.focus, 0);
  EXPECT_EQ(r.iris, 32768);
  EXPECT_EQ(r.zoom, kNormalisedCounts);
  EXPECT_EQ(r.focus_distance_m, 2.5);
  EXPECT_EQ(r.f_stop, 2.8);
  EXPECT_EQ(r.focal_length_mm, 35.2);
  EXPECT_GE(r.t_ns, before);
  EXPECT_LE(r.t_ns, test::now_ns());
  EXPECT_TRUE(rx.status().connected);
}

TEST(OpenTrackIoReceiver, MalformedSamplesAreCountedWithTheField) {
  OpenTrackIoReceiver rx(loopback());
  test::RawSender tx(rx.port());
  auto corrupt = sample(1);
  corrupt.back() ^= 0x20; // payload byte: checksum mismatch
  ASSERT_TRUE(tx.send(corrupt));
  ASSERT_TRUE(tx.send(payload(R"({"lens":{"fStop":-1}})", 2)));
  std::vector<EncoderReading> out;
  settle(rx, 2, out);
  EXPECT_TRUE(out.empty());
  const EncoderStatus s = rx.status();
  EXPECT_EQ(s.malformed, 2u);
  EXPECT_FALSE(s.connected);
  EXPECT_NE(s.detail.find("malformed datagram from 127.0.0.1:"), std::string::npos) << s.detail;
  EXPECT_NE(s.detail.find("lens.fStop"), std::string::npos) << s.detail;
}

TEST(OpenTrackIoReceiver, TrackerOnlySampleIsNeitherReadingNorMalformed) {
  OpenTrackIoReceiver rx(loopback());
  test::RawSender tx(rx.port());
  ASSERT_TRUE(tx.send(payload(R"({"tracker":{"status":"ok"}})", 1)));
  ASSERT_TRUE(tx.send(sample(2)));
  const std::vector<EncoderReading> got = test::collect(rx, 1);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(rx.status().malformed, 0u);
  EXPECT_EQ(rx.status().readings, 1u);
  EXPECT_EQ(rx.status().lost, 0u) << "the tracker-only sample still counts in the sequence";
}

TEST(OpenTrackIoReceiver, SequenceGapsCountAsLost) {
  OpenTrackIoReceiver rx(loopback());
  test::RawSender tx(rx.port());
  // 65534, 65535, (0 missing), 1, (2, 3 missing), 4: wraps and loses 3.
  for (const std::uint16_t seq : {65534, 65535, 1, 4}) {
    ASSERT_TRUE(tx.send(sample(seq)));
  }
  EXPECT_EQ(test::collect(rx, 4).size(), 4u);
  EXPECT_EQ(rx.status().lost, 3u);

  // A step backwards (late, repeated or a restarted sender) resynchronises
  // without counting; counting resumes from there.
  for (const std::uint16_t seq : {2, 3, 5}) {
    ASSERT_TRUE(tx.send(sample(seq)));
  }
  EXPECT_EQ(test::collect(rx, 3).size(), 3u);
  // After the resync at 2 and 3, the step to 5 counts 4 as missing although it
  // came earlier: a reordering costs one false count, never a dropped reading.
  EXPECT_EQ(rx.status().lost, 4u);
}

TEST(OpenTrackIoReceiver, SilentSocketWaitsForTheTimeoutAndReturns) {
  OpenTrackIoReceiver rx(loopback());
  std::vector<EncoderReading> out;
  const std::int64_t start = test::now_ns();
  rx.poll(milliseconds(40), out);
  const std::int64_t waited = test::now_ns() - start;
  EXPECT_TRUE(out.empty());
  EXPECT_GE(waited, 40'000'000);
  EXPECT_LT(waited, 5'000'000'000);
}

TEST(OpenTrackIoReceiver, RejectsGroupOutsideMulticastRange) {
  OpenTrackIoReceiverConfig c = loopback();
  c.multicast_group = "10.1.2.3";
  try {
    OpenTrackIoReceiver rx(c);
    FAIL() << "joined a unicast address";
  } catch (const std::invalid_argument &e) {
    EXPECT_NE(std::string(e.what()).find("opentrackio udp 127.0.0.1:0: multicast group: 10.1.2.3"),
              std::string::npos)
        << e.what();
  }
}

TEST(OpenTrackIoReceiver, BindConflictNamesTheSocket) {
  OpenTrackIoReceiver first(loopback());
  OpenTrackIoReceiverConfig same = loopback();
  same.port = first.port();
  try {
    OpenTrackIoReceiver second(same);
    FAIL() << "a second unicast receiver bound the same port";
  } catch (const std::system_error &e) {
    EXPECT_EQ(std::string(e.what()).rfind(
                  "opentrackio udp 127.0.0.1:" + std::to_string(first.port()) + ": bind: ", 0),
              0u)
        << e.what();
  }
}

} // namespace
} // namespace camhead::hal::lens
