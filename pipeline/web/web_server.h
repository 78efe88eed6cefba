// The operator page's HTTP server (web_module_abi.h), from libcamhead_web.so:
// a module opened at run time, as the marker tracker is, so that camhead
// starts where libevent and libjpeg-turbo are not installed and only a run
// that asks for the page needs them.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "web_module_abi.h"

namespace camhead::pipeline::web {

// The module cannot be opened, the server cannot start, or a password not hashed.
class WebError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// Serves `host` until the server is destroyed (throws WebError).
[[nodiscard]] std::unique_ptr<web_module::Server>
start_web_server(const web_module::ServerConfig &config, web_module::Host &host);

// The module's file name, and why it cannot be opened ("" when it can):
// for `camhead devices`.
[[nodiscard]] const char *web_module_name();
[[nodiscard]] std::string web_module_problem();

// `password`'s crypt(3) hash, for a password file (throws WebError).
[[nodiscard]] std::string hash_password(const std::string &password);

} // namespace camhead::pipeline::web
