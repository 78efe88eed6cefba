#include "http_auth.h"

#include <algorithm>
#include <cstring>
#include <string_view>

#include <crypt.h>

namespace camhead::pipeline::web {
namespace {

constexpr std::int64_t kSecondNs = 1'000'000'000;
constexpr int kLongestLockS = 300;

// Equal without a timing that says where two strings first differ.
bool same(std::string_view a, std::string_view b) {
  if (a.size() != b.size())
    return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

// RFC 4648 base64, or nothing for text that is not.
std::optional<std::string> base64_decode(std::string_view text) {
  std::string out;
  std::uint32_t bits = 0;
  int have = 0;
  std::size_t padding = 0;
  for (const char c : text) {
    int value;
    if (c >= 'A' && c <= 'Z')
      value = c - 'A';
    else if (c >= 'a' && c <= 'z')
      value = c - 'a' + 26;
    else if (c >= '0' && c <= '9')
      value = c - '0' + 52;
    else if (c == '+')
      value = 62;
    else if (c == '/')
      value = 63;
    else if (c == '=') {
      ++padding;
      continue;
    } else
      return std::nullopt;
    if (padding > 0)
      return std::nullopt; // data after padding
    bits = (bits << 6) | std::uint32_t(value);
    have += 6;
    if (have >= 8) {
      have -= 8;
      out += char((bits >> have) & 0xff);
    }
  }
  if (padding > 2)
    return std::nullopt;
  return out;
}

// crypt_rn, not crypt_r: the sanitizers intercept crypt_r, and their
// interceptor finds no libcrypt in a module opened after start (a crash).
bool password_matches(const std::string &password, const std::string &hash) {
  crypt_data data{};
  const char *result = crypt_rn(password.c_str(), hash.c_str(), &data, sizeof data);
  return result != nullptr && result[0] != '*' && same(result, hash);
}

} // namespace

Credentials HttpAuth::check(const char *authorization, const std::string &peer,
                            std::int64_t now_ns) {
  if (hash_.empty())
    return Credentials::none_needed;
  if (authorization == nullptr)
    return Credentials::missing;
  const std::string_view value(authorization);
  if (!accepted_.empty() && same(value, accepted_)) {
    failures_.erase(peer);
    return Credentials::good;
  }
  constexpr std::string_view kBasic = "Basic ";
  std::optional<std::string> pair;
  if (value.size() > kBasic.size() && value.substr(0, kBasic.size()) == kBasic &&
      value.size() < 1024)
    pair = base64_decode(value.substr(kBasic.size()));
  // user:password; the user name is not checked (one operator password).
  const std::size_t colon = pair ? pair->find(':') : std::string::npos;
  if (colon != std::string::npos && password_matches(pair->substr(colon + 1), hash_)) {
    accepted_ = value;
    failures_.erase(peer);
    return Credentials::good;
  }
  Failures &f = failures_[peer];
  ++f.count;
  if (f.count >= kFreeTries) {
    const int lock_s = std::min(kLongestLockS, 1 << std::min(f.count - kFreeTries, 9));
    f.until_ns = now_ns + lock_s * kSecondNs;
  }
  if (failures_.size() > 4096) // a flood from many addresses: forget the oldest state
    failures_.clear();
  return Credentials::wrong;
}

std::optional<int> HttpAuth::locked(const std::string &peer, std::int64_t now_ns) const {
  const auto found = failures_.find(peer);
  if (found == failures_.end() || found->second.until_ns <= now_ns)
    return std::nullopt;
  return int((found->second.until_ns - now_ns + kSecondNs - 1) / kSecondNs);
}

std::string hash_password(const std::string &password, std::string &error) {
  char salt[CRYPT_GENSALT_OUTPUT_SIZE];
  if (crypt_gensalt_rn("$y$", 0, nullptr, 0, salt, sizeof salt) == nullptr) {
    error = std::string("no salt for the password: ") + std::strerror(errno);
    return {};
  }
  crypt_data data{};
  const char *hash = crypt_rn(password.c_str(), salt, &data, sizeof data);
  if (hash == nullptr || hash[0] == '*') {
    error = "the password could not be hashed";
    return {};
  }
  return hash;
}

} // namespace camhead::pipeline::web
