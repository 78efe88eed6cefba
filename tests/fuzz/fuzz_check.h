// What the libFuzzer targets share: a check that makes libFuzzer keep the
// input (abort is reported as a crash, with the input saved), and the
// input as text for the readers that take text.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

namespace camhead::fuzz {

inline void check(bool ok) {
  if (!ok)
    std::abort();
}

inline std::string text_of(const std::uint8_t *data, std::size_t size) {
  return {reinterpret_cast<const char *>(data), size};
}

} // namespace camhead::fuzz
