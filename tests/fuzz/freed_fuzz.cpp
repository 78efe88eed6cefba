// libFuzzer target for the FreeD D1 parser: any byte string must be rejected
// with a reason or parsed, never crash or hit undefined behaviour, and what
// parses must re-encode to the very same bytes (every wire field is recovered
// exactly).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "camhead/hal/lens/network/freed.h"

namespace {

using namespace camhead::hal::lens;

void check(bool ok) {
  if (!ok) {
    std::abort(); // libFuzzer reports the input as a crash
  }
}

void check_round_trip(std::span<const std::uint8_t> input) {
  const FreedParseResult r = parse_freed_d1(input);
  check(r.message.has_value() == (r.error == FreedError::none));
  check(r.message.has_value() == r.detail.empty());
  if (r) {
    const auto again = encode_freed_d1(*r.message);
    check(std::equal(again.begin(), again.end(), input.begin(), input.end()));
  }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  const std::span<const std::uint8_t> input(data, size);
  check_round_trip(input);

  // The same bytes made into a valid D1 (type byte and checksum fixed), so
  // that every input also exercises the field decoding, not only the guards.
  if (size >= kFreedD1Size - 1) {
    std::array<std::uint8_t, kFreedD1Size> fixed{};
    std::copy_n(data, kFreedD1Size - 1, fixed.begin());
    fixed[0] = kFreedD1Type;
    fixed[kFreedD1Size - 1] = freed_checksum(std::span(fixed).first(kFreedD1Size - 1));
    check(parse_freed_d1(fixed).message.has_value());
    check_round_trip(fixed);
  }
  return 0;
}
