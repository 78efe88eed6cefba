// libFuzzer target for the USB lens board's codec (hal/lens/usb): any byte
// string must be rejected with a reason or parsed, never crash or hit
// undefined behaviour, and what parses must re-encode to the very same bytes.
// The same bytes also drive the clock mapper and the sequence tracker as a
// stream of (sequence, device time, receive delay) records, which must keep
// their promises whatever the board sends.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "camhead/hal/lens/usb/device_clock.h"
#include "camhead/hal/lens/usb/sequence_tracker.h"
#include "camhead/hal/lens/usb/usb_lens_protocol.h"

namespace {

using namespace camhead::hal::lens;

void check(bool ok) {
  if (!ok) {
    std::abort(); // libFuzzer reports the input as a crash
  }
}

void check_report(std::span<const std::uint8_t> input) {
  const ReportParseResult r = parse_report(input);
  check(r.report.has_value() == (r.error == ReportError::none));
  check(r.report.has_value() == r.detail.empty());
  if (r) {
    const auto again = encode_report(*r.report);
    check(std::equal(again.begin(), again.end(), input.begin(), input.end()));
  }
}

void check_board_info(std::span<const std::uint8_t> input) {
  const BoardInfoParseResult r = parse_board_info(input);
  check(r.info.has_value() == (r.error == ReportError::none));
  check(r.info.has_value() == r.detail.empty());
  if (r) {
    const auto again = encode_board_info(*r.info);
    check(std::equal(again.begin(), again.end(), input.begin(), input.end()));
  }
}

std::uint32_t u32_at(const std::uint8_t *p) {
  return std::uint32_t{p[0]} | (std::uint32_t{p[1]} << 8) | (std::uint32_t{p[2]} << 16) |
         (std::uint32_t{p[3]} << 24);
}

// Records of 10 bytes: sequence (4), device time (4), receive step (2, in
// 10 us units). Receive times are CLOCK_MONOTONIC-like: from one day of
// uptime, never going back, as the transport delivers them.
void check_stream(std::span<const std::uint8_t> input) {
  DeviceClockMapper clock;
  SequenceTracker sequence;
  std::int64_t receive_ns = 86'400'000'000'000;
  std::int64_t last_out = 0;
  for (std::size_t at = 0; at + 10 <= input.size(); at += 10) {
    const std::uint8_t *p = input.data() + at;
    (void)sequence.push(u32_at(p));
    receive_ns += std::int64_t{static_cast<std::uint16_t>(p[8] | (p[9] << 8))} * 10'000;
    const std::int64_t out = clock.map(u32_at(p + 4), receive_ns);
    // Never after receipt, except by the 1 ns steps that keep it strictly
    // increasing when receive times repeat.
    check(out <= std::max(receive_ns, last_out + 1));
    last_out = out;
  }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  const std::span<const std::uint8_t> input(data, size);
  check_report(input);
  check_board_info(input);

  // The same bytes made into a valid report (framing and CRC fixed, reserved
  // bits cleared), so that every input also exercises the field decoding,
  // not only the guards.
  if (size >= kUsbLensReportSize - 2) {
    std::array<std::uint8_t, kUsbLensReportSize> fixed{};
    std::copy_n(data, kUsbLensReportSize - 2, fixed.begin());
    fixed[0] = static_cast<std::uint8_t>(kUsbLensMagic);
    fixed[1] = static_cast<std::uint8_t>(kUsbLensMagic >> 8);
    fixed[2] = kUsbLensVersion;
    fixed[3] &= kAxesAll;
    fixed[24] &= static_cast<std::uint8_t>(kStatusDefinedBits);
    fixed[25] &= static_cast<std::uint8_t>(kStatusDefinedBits >> 8);
    const std::uint16_t crc =
        crc16_ccitt_false(std::span<const std::uint8_t>(fixed).first(kUsbLensReportSize - 2));
    fixed[26] = static_cast<std::uint8_t>(crc);
    fixed[27] = static_cast<std::uint8_t>(crc >> 8);
    check(parse_report(fixed).report.has_value());
    check_report(fixed);
  }
  check_stream(input);
  return 0;
}
