// libFuzzer target for the operator page's credential check
// (pipeline/web/libevent/http_auth.h), the one reader of the page's own
// that takes a request's bytes (libevent parses the rest): any
// Authorization value is refused or taken, never a crash; only the right
// password is taken; and any user name with it is.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include <crypt.h>

#include "http_auth.h"

namespace {

using camhead::pipeline::web::Credentials;
using camhead::pipeline::web::HttpAuth;

void check(bool ok) {
  if (!ok)
    std::abort(); // libFuzzer reports the input as a crash
}

std::string base64(const std::string &text) {
  static const char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < text.size(); i += 3) {
    const std::uint32_t v = std::uint32_t(std::uint8_t(text[i])) << 16 |
                            std::uint32_t(std::uint8_t(text[i + 1])) << 8 |
                            std::uint8_t(text[i + 2]);
    for (int k = 18; k >= 0; k -= 6)
      out += kDigits[(v >> k) & 63];
  }
  if (i + 1 == text.size()) {
    const std::uint32_t v = std::uint32_t(std::uint8_t(text[i])) << 16;
    out += std::string{kDigits[(v >> 18) & 63], kDigits[(v >> 12) & 63], '=', '='};
  } else if (i + 2 == text.size()) {
    const std::uint32_t v =
        std::uint32_t(std::uint8_t(text[i])) << 16 | std::uint32_t(std::uint8_t(text[i + 1])) << 8;
    out +=
        std::string{kDigits[(v >> 18) & 63], kDigits[(v >> 12) & 63], kDigits[(v >> 6) & 63], '='};
  }
  return out;
}

// SHA-256 crypt at its fewest rounds: the fuzzer's speed, not a password's.
const std::string &hash() {
  static const std::string h = [] {
    crypt_data data{};
    return std::string(crypt_rn("right password", "$5$rounds=1000$fuzzsalt$", &data, sizeof data));
  }();
  return h;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  const std::string input(reinterpret_cast<const char *>(data), size);
  const std::string value = input.substr(0, input.find('\0')); // a header has no NUL
  HttpAuth auth(hash());
  const Credentials c = auth.check(value.c_str(), "peer", 0);
  check(c == Credentials::wrong || c == Credentials::good);
  // Taken only with the right password (its hash never collides here).
  if (c == Credentials::good)
    check(value.rfind("Basic ", 0) == 0 && value.find(base64("")) != std::string::npos);
  // Any user name without a colon, with the right password, is taken.
  std::string user;
  for (const char ch : value)
    if (ch != ':')
      user += ch;
  if (user.size() < 600) {
    const std::string good = "Basic " + base64(user + ":right password");
    check(auth.check(good.c_str(), "peer", 0) == Credentials::good);
  }
  // The wrong one, over and over, locks the peer out; another peer is heard.
  for (int i = 0; i < HttpAuth::kFreeTries; ++i)
    check(auth.check("Basic d3Jvbmc=", "peer", 0) == Credentials::wrong);
  check(auth.locked("peer", 0).has_value() && !auth.locked("other", 0).has_value());
  return 0;
}
