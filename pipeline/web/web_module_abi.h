// What camhead (operator_page.cpp, web_loader.cpp) and the web module
// (libcamhead_web.so, which links libevent and libjpeg-turbo) agree on: one
// extern "C" factory returning a table of virtual functions, as the marker
// and libcamera modules do. The module serves HTTP; camhead says what there
// is to serve (Host). Exceptions do not cross; kAbiVersion changes whenever
// this header, web_feed.h or preview_image.h does.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "preview_image.h"
#include "web_feed.h"

namespace camhead::pipeline::web_module {

inline constexpr int kAbiVersion = 2; // 2: the region view
inline constexpr const char *kFactorySymbol = "camhead_web_module";

struct ServerConfig {
  std::string host = "127.0.0.1"; // an address to bind (numeric), or "localhost"
  std::uint16_t port = 8080;      // 0: any free one (tests)
  // A crypt(3) hash ("$y$..." as in /etc/shadow) every request must give the
  // password of (HTTP Basic); empty: none asked (camhead allows that only
  // on a loopback address).
  std::string password_hash;
};

// The server's own counts, for the state and /metrics.
struct HttpStats {
  std::uint64_t requests = 0;
  std::uint64_t refused_credentials = 0; // a wrong password (each slows its sender)
  std::uint64_t missing_credentials = 0; // none given where one is needed
  std::uint64_t refused_requests = 0;    // malformed, too large, too many, unknown
  std::uint64_t preview_frames = 0;      // JPEG frames sent to preview clients
  std::uint64_t jpeg_frames = 0;         // JPEG encodes (one per preview frame, shared)
  double jpeg_seconds = 0.0;             // their time, summed
  int stream_clients = 0;                // preview and event streams open now
};

struct Reply {
  int status = 200;
  std::string body; // JSON
};

// camhead's side. Called on the server's thread only.
class Host {
public:
  // Someone started (+1) or stopped (-1) watching `view`.
  virtual void watch(pipeline::web::View view, int delta) = 0;
  // The newest preview of `view` (PreviewImage::valid false before the
  // first): the newest frame the frame loop handed over since the last
  // call, shrunk.
  virtual const pipeline::web::PreviewImage &preview(pipeline::web::View view) = 0;
  // GET /api/state: the run now, as JSON.
  virtual std::string state_json(const HttpStats &http) = 0;
  // GET /api/history: the last minute's lens and latency, as JSON.
  virtual std::string history_json() = 0;
  // GET /metrics: Prometheus's text format, the server's counts included.
  virtual std::string metrics(const HttpStats &http) = 0;
  // POST /api/NAME with a JSON body: an operator's action.
  virtual Reply action(std::string_view name, std::string_view body) = 0;

protected:
  ~Host() = default;
};

class Server {
public:
  virtual ~Server() = default; // stops serving, closes every connection
  // "http://127.0.0.1:8080/" as bound (the port chosen, for port 0).
  [[nodiscard]] virtual std::string url() const = 0;
};

class Module {
public:
  // Serves `host` on its own thread until the Server is destroyed; null with
  // `error` saying why (the address is taken, ...).
  virtual std::unique_ptr<Server> start(const ServerConfig &config, Host &host,
                                        std::string &error) = 0;
  // `password`'s crypt(3) hash with a new random salt (yescrypt, as
  // Debian's /etc/shadow), into `hash`; false with `error` saying why.
  virtual bool hash_password(const std::string &password, std::string &hash,
                             std::string &error) = 0;

protected:
  ~Module() = default; // the module owns its one instance
};

using Factory = Module *(*)(int abi_version);

} // namespace camhead::pipeline::web_module
