// Explains why an OpenTrackIO JSON payload did not parse. Private to the
// library: the JSON library never appears in a public header.
#pragma once

#include <cstdint>
#include <span>

#include "camhead/hal/lens/network/opentrackio.h"

namespace camhead::hal::lens::detail {

// Re-reads a payload that the non-throwing DOM parse rejected (it only says
// "discarded") and reports where and why: malformed_json with the byte
// position, the offending token and the enclosing key path, or non_finite
// naming the field when a number literal such as 1e999 overflows a double.
// Called on the error path only, so the second pass costs nothing in the
// common case.
[[nodiscard]] OpenTrackIoParseResult describe_json_error(std::span<const std::uint8_t> payload);

} // namespace camhead::hal::lens::detail
