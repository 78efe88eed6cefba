// Who may reach the operator page: where it listens (`--http ADDR:PORT`, a
// board's "http") and the password that anything but a loopback address
// asks for, read from a file only its owner can read (as ssh reads a key).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

namespace camhead::pipeline::web {

class WebAccessError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

struct ListenAddress {
  std::string host; // numeric ("127.0.0.1", "0.0.0.0", "::1") or "localhost"
  std::uint16_t port = 0;
};

// Where a run serves its operator page, and who may see it.
struct WebOptions {
  ListenAddress listen;
  // The password file; needed for an address other than loopback.
  std::optional<std::filesystem::path> password_file;
  // Where the page's record button writes its takes (relative: to the
  // working directory, /var/lib/camhead for the service).
  std::filesystem::path recordings = "recordings";
};

// "8080" (on 127.0.0.1), "127.0.0.1:8080", "0.0.0.0:8080", "[::]:8080",
// "localhost:8080"; `what` names the option or field in errors (throws
// WebAccessError).
[[nodiscard]] ListenAddress parse_listen(const std::string &text, const std::string &what);
// Whether only this machine can reach `host` (127.0.0.0/8, ::1, localhost).
[[nodiscard]] bool is_loopback(const std::string &host);

// The crypt(3) hash in `file` (one line, as `camhead web-password` writes
// it). Throws WebAccessError naming the file when it is missing, readable
// or writable by anyone but its owner, or holds no hash.
[[nodiscard]] std::string read_password_file(const std::filesystem::path &file);
// Writes `hash` to `file` (replacing it whole, mode 0600, the owner of the
// file it replaces kept when run as root; throws WebAccessError naming it).
void write_password_file(const std::filesystem::path &file, const std::string &hash);

} // namespace camhead::pipeline::web
