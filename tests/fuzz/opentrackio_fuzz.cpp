// libFuzzer target for the OpenTrackIO parser: any byte string must be
// rejected with a reason or parsed, never crash or hit undefined behaviour,
// and a parsed sample must survive encode -> parse unchanged.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "camhead/hal/lens/network/opentrackio.h"

namespace {

using namespace camhead::hal::lens;

void check(bool ok) {
  if (!ok) {
    std::abort(); // libFuzzer reports the input as a crash
  }
}

void check_result(const OpenTrackIoParseResult &r) {
  check(r.sample.has_value() == (r.error == OpenTrackIoError::none));
  check(r.sample.has_value() == r.detail.empty());
  if (!r) {
    return;
  }
  // Strings came from valid JSON and doubles print in round-trip form, so the
  // re-encoded sample must parse back equal. Empty: the re-encoded JSON (with
  // its protocol object) no longer fits one datagram, which is legitimate.
  const auto again = encode_opentrackio(*r.sample);
  if (!again.empty()) {
    const OpenTrackIoParseResult back = parse_opentrackio(again);
    check(back.sample.has_value() && *back.sample == *r.sample);
  }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  const std::span<const std::uint8_t> input(data, size);
  // The input as a whole datagram: header checks.
  check_result(parse_opentrackio(input));
  // The input as a payload behind a valid header, so that the fuzzer reaches
  // the JSON and field checks without having to solve Fletcher-16 first.
  const auto wrapped = encode_opentrackio_datagram(input, 1);
  if (!wrapped.empty()) {
    check_result(parse_opentrackio(wrapped));
  }
  return 0;
}
