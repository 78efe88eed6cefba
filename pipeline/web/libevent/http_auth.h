// The operator page's credential check (web_module_abi.h, ServerConfig):
// HTTP Basic with a password checked against its crypt(3) hash, and a
// sender that gives wrong passwords slowed down: after kFreeTries wrong
// ones in a row every request from its address is refused (429) for a time
// that doubles with each further wrong one, up to five minutes.
//
// Thread safety: one thread (the server's).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>

namespace camhead::pipeline::web {

enum class Credentials { none_needed, good, missing, wrong };

class HttpAuth {
public:
  static constexpr int kFreeTries = 5;

  // `hash` empty: no password asked.
  explicit HttpAuth(std::string hash) : hash_(std::move(hash)) {}

  // Checks an Authorization header's value (null: none) from `peer`.
  Credentials check(const char *authorization, const std::string &peer, std::int64_t now_ns);
  // Seconds `peer` must wait before it is heard again, or nothing.
  [[nodiscard]] std::optional<int> locked(const std::string &peer, std::int64_t now_ns) const;

private:
  struct Failures {
    int count = 0;
    std::int64_t until_ns = 0;
  };
  std::string hash_;
  // The last Authorization value that checked out: the next requests of a
  // browser that sends it each time cost a comparison, not a yescrypt.
  std::string accepted_;
  std::unordered_map<std::string, Failures> failures_;
};

// `password`'s crypt(3) hash with a fresh salt (yescrypt); empty with
// `error` on failure.
std::string hash_password(const std::string &password, std::string &error);

} // namespace camhead::pipeline::web
