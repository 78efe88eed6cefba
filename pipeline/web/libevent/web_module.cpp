// libcamhead_web.so (web_server.h): the operator page's HTTP server on
// libevent's evhttp, one event loop on one thread of its own (as ustreamer
// serves its MJPEG), and libjpeg-turbo for the preview. Its one exported
// symbol is the factory (web_module_abi.h); everything else is hidden.
//
// A preview client is sent the newest preview frame only once it has taken
// the last one (evhttp_send_reply_chunk_with_cb: the callback comes when
// the connection's output has drained), so a slow client gets fewer frames
// and one that never reads holds one frame in its socket until the write
// timeout closes it; neither holds anything of the frame loop's. A
// preview frame is encoded once, whoever watches it.
#include <atomic>
#include <cstdio>
#include <cstring>
#include <list>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <arpa/inet.h>
#include <event2/buffer.h>
#include <event2/event.h>
#include <event2/http.h>
#include <event2/keyvalq_struct.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <time.h>
#include <turbojpeg.h>

#include "../web_module_abi.h"
#include "embedded_files.h"
#include "http_auth.h"

namespace camhead::pipeline::web {
namespace {

using web_module::HttpStats;

constexpr const char *kBoundary = "camheadframe";
constexpr int kMaxStreamClients = 64;
constexpr std::size_t kMaxHeaders = 8 * 1024;
constexpr std::size_t kMaxBody = 64 * 1024;
// A connection whose reads or writes stall this long is closed (a preview
// client that stopped reading, a request sent a byte a minute).
constexpr int kTimeoutS = 10;
constexpr int kJpegQuality = 80;
constexpr std::int64_t kSnapshotWaitNs = 3'000'000'000;
constexpr std::int64_t kEventIntervalNs = 1'000'000'000;

std::int64_t now_ns() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return std::int64_t(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

const char *content_type(const std::string &name) {
  if (name.ends_with(".html"))
    return "text/html; charset=utf-8";
  if (name.ends_with(".css"))
    return "text/css; charset=utf-8";
  if (name.ends_with(".js"))
    return "text/javascript; charset=utf-8";
  return "application/octet-stream";
}

const EmbeddedFile *page_file(const std::string &path) {
  const std::string name = path == "/" ? "index.html" : path.substr(1);
  for (const EmbeddedFile *f = kEmbeddedFiles; f->name != nullptr; ++f)
    if (name == f->name)
      return f;
  return nullptr;
}

// One JPEG encoder, its output buffer made once at the largest size.
class JpegEncoder {
public:
  JpegEncoder() : handle_(tjInitCompress()) {}
  ~JpegEncoder() {
    if (handle_ != nullptr)
      tjDestroy(handle_);
    tjFree(buffer_);
  }
  JpegEncoder(const JpegEncoder &) = delete;
  JpegEncoder &operator=(const JpegEncoder &) = delete;

  // `image` as a JPEG (valid until the next call), or empty on failure.
  std::span<const unsigned char> encode(const PreviewImage &image) {
    const unsigned long needed = tjBufSize(image.width, image.height, TJSAMP_420);
    if (handle_ == nullptr || needed == static_cast<unsigned long>(-1))
      return {};
    if (needed > capacity_) { // the first frame, or a larger one
      tjFree(buffer_);
      buffer_ = tjAlloc(int(needed));
      capacity_ = buffer_ != nullptr ? needed : 0;
    }
    unsigned long size = capacity_;
    if (buffer_ == nullptr ||
        tjCompress2(handle_, image.rgb.data(), image.width, 0, image.height, TJPF_RGB, &buffer_,
                    &size, TJSAMP_420, kJpegQuality, TJFLAG_NOREALLOC | TJFLAG_FASTDCT) != 0)
      return {};
    return {buffer_, size};
  }

private:
  tjhandle handle_;
  unsigned char *buffer_ = nullptr;
  unsigned long capacity_ = 0;
};

class HttpServer;

// A connection the server writes to over time: a preview stream, an event
// stream, or a snapshot waiting for its frame.
struct StreamClient {
  enum class Kind { mjpeg, events, snapshot };
  HttpServer *server = nullptr;
  evhttp_request *request = nullptr;
  Kind kind = Kind::mjpeg;
  View view = View::composite;
  std::uint64_t last_frame = ~std::uint64_t(0);
  bool writing = false;    // a chunk is on its way: wait for it to drain
  std::int64_t due_ns = 0; // events: the next; snapshot: give up
};

class HttpServer final : public web_module::Server {
public:
  HttpServer(const web_module::ServerConfig &config, web_module::Host &host)
      : host_(host), auth_(config.password_hash) {}

  bool start(const web_module::ServerConfig &config, std::string &error) {
    base_ = event_base_new();
    http_ = base_ != nullptr ? evhttp_new(base_) : nullptr;
    if (http_ == nullptr) {
      error = "libevent could not make an event loop";
      return false;
    }
    evhttp_set_max_headers_size(http_, kMaxHeaders);
    evhttp_set_max_body_size(http_, kMaxBody);
    evhttp_set_timeout(http_, kTimeoutS);
    evhttp_set_allowed_methods(http_, EVHTTP_REQ_GET | EVHTTP_REQ_HEAD | EVHTTP_REQ_POST);
    evhttp_set_gencb(http_, &HttpServer::on_request, this);
    const std::string host = config.host == "localhost" ? "127.0.0.1" : config.host;
    evhttp_bound_socket *bound = evhttp_bind_socket_with_handle(http_, host.c_str(), config.port);
    if (bound == nullptr) {
      error = "cannot listen on " + config.host + ":" + std::to_string(config.port) + ": " +
              std::strerror(errno) +
              " (another program on that port? --http ADDR:PORT picks "
              "another)";
      return false;
    }
    sockaddr_storage address{};
    socklen_t length = sizeof address;
    getsockname(evhttp_bound_socket_get_fd(bound), reinterpret_cast<sockaddr *>(&address), &length);
    const int port = address.ss_family == AF_INET6
                         ? ntohs(reinterpret_cast<sockaddr_in6 *>(&address)->sin6_port)
                         : ntohs(reinterpret_cast<sockaddr_in *>(&address)->sin_port);
    const bool v6 = host.find(':') != std::string::npos;
    url_ = "http://" + (v6 ? "[" + host + "]" : host) + ":" + std::to_string(port) + "/";
    tick_ = event_new(base_, -1, EV_PERSIST, &HttpServer::on_tick, this);
    const timeval every{0, 10'000};
    event_add(tick_, &every);
    thread_ = std::thread([this] { event_base_dispatch(base_); });
    return true;
  }

  ~HttpServer() override {
    stop_ = true;
    if (thread_.joinable())
      thread_.join();
    for (StreamClient &client : clients_)
      forget(client);
    clients_.clear();
    if (tick_ != nullptr)
      event_free(tick_);
    if (http_ != nullptr)
      evhttp_free(http_);
    if (base_ != nullptr)
      event_base_free(base_);
  }

  std::string url() const override { return url_; }

private:
  static void on_request(evhttp_request *request, void *self) {
    static_cast<HttpServer *>(self)->handle(request);
  }
  static void on_tick(evutil_socket_t, short, void *self) {
    static_cast<HttpServer *>(self)->tick();
  }
  static void on_close(evhttp_connection *, void *arg) {
    auto *client = static_cast<StreamClient *>(arg);
    client->server->closed(client);
  }
  static void on_written(evhttp_connection *, void *arg) {
    static_cast<StreamClient *>(arg)->writing = false;
  }

  void reply(evhttp_request *request, int status, const char *reason, const char *type,
             std::string_view body) {
    evkeyvalq *headers = evhttp_request_get_output_headers(request);
    evhttp_add_header(headers, "Content-Type", type);
    evhttp_add_header(headers, "Cache-Control", "no-store");
    evhttp_add_header(headers, "X-Content-Type-Options", "nosniff");
    evbuffer *buffer = evbuffer_new();
    evbuffer_add(buffer, body.data(), body.size());
    evhttp_send_reply(request, status, reason, buffer);
    evbuffer_free(buffer);
  }
  void error(evhttp_request *request, int status, const char *reason, const std::string &why) {
    reply(request, status, reason, "application/json",
          "{\"error\":\"" + why + "\"}"); // `why` is camhead's own text, without quotes
  }

  static std::string peer_of(evhttp_request *request) {
    char *address = nullptr;
    ev_uint16_t port = 0;
    evhttp_connection_get_peer(evhttp_request_get_connection(request), &address, &port);
    return address != nullptr ? address : "";
  }

  void handle(evhttp_request *request) {
    ++stats_.requests;
    const std::int64_t now = now_ns();
    const std::string peer = peer_of(request);
    if (const std::optional<int> wait = auth_.locked(peer, now)) {
      ++stats_.refused_credentials;
      evhttp_add_header(evhttp_request_get_output_headers(request), "Retry-After",
                        std::to_string(*wait).c_str());
      return error(request, 429, "Too Many Requests",
                   "too many wrong passwords from this address: wait " + std::to_string(*wait) +
                       " s");
    }
    const Credentials credentials = auth_.check(
        evhttp_find_header(evhttp_request_get_input_headers(request), "Authorization"), peer, now);
    if (credentials == Credentials::missing || credentials == Credentials::wrong) {
      ++(credentials == Credentials::missing ? stats_.missing_credentials
                                             : stats_.refused_credentials);
      evhttp_add_header(evhttp_request_get_output_headers(request), "WWW-Authenticate",
                        "Basic realm=\"camhead\", charset=\"UTF-8\"");
      return error(request, 401, "Unauthorized", "this page needs the head's password");
    }
    // Without a password only this machine reaches the page, but a page in
    // its browser from another site could, through a name that resolves to
    // this machine (DNS rebinding): such a request names that site.
    if (credentials == Credentials::none_needed && !local_host(request))
      return refuse(request, 403, "Forbidden",
                    "this page answers to localhost and this machine's loopback addresses only");
    const evhttp_uri *uri = evhttp_request_get_evhttp_uri(request);
    const char *raw_path = uri != nullptr ? evhttp_uri_get_path(uri) : nullptr;
    const std::string path = raw_path != nullptr && raw_path[0] != '\0' ? raw_path : "/";
    const evhttp_cmd_type method = evhttp_request_get_command(request);

    if (method == EVHTTP_REQ_POST) {
      if (!path.starts_with("/api/") || path.size() > 64)
        return refuse(request, 404, "Not Found", "no such action");
      // JSON only: a form on another site cannot send it without asking
      // first (a CORS preflight, which this server does not answer), so a
      // browser that holds the password cannot be made to act for it.
      const char *type =
          evhttp_find_header(evhttp_request_get_input_headers(request), "Content-Type");
      if (type == nullptr || std::string_view(type).substr(0, 16) != "application/json")
        return refuse(request, 415, "Unsupported Media Type",
                      "an action's body is JSON (Content-Type: application/json)");
      evbuffer *input = evhttp_request_get_input_buffer(request);
      std::string body(evbuffer_get_length(input), '\0');
      evbuffer_copyout(input, body.data(), body.size());
      const web_module::Reply r = host_.action(path.substr(5), body);
      if (r.status >= 400)
        ++stats_.refused_requests;
      return reply(request, r.status, nullptr, "application/json", r.body);
    }
    if (const EmbeddedFile *file = page_file(path)) {
      evkeyvalq *headers = evhttp_request_get_output_headers(request);
      evhttp_add_header(headers, "Content-Security-Policy",
                        "default-src 'self'; img-src 'self' blob:; object-src 'none'; "
                        "frame-ancestors 'none'");
      evhttp_add_header(headers, "Referrer-Policy", "no-referrer");
      return reply(request, 200, "OK", content_type(file->name),
                   {reinterpret_cast<const char *>(file->bytes), file->size});
    }
    if (path == "/api/state")
      return reply(request, 200, "OK", "application/json", host_.state_json(stats()));
    if (path == "/api/history")
      return reply(request, 200, "OK", "application/json", host_.history_json());
    if (path == "/metrics")
      return reply(request, 200, "OK", "text/plain; version=0.0.4; charset=utf-8",
                   host_.metrics(stats()));
    if (path == "/api/events")
      return stream(request, StreamClient::Kind::events, View::composite);
    if (path == "/stream.mjpeg" || path == "/snapshot.jpg") {
      const std::optional<View> view = view_of(uri);
      if (!view)
        return refuse(request, 400, "Bad Request", "view: composite, camera or region");
      return stream(request,
                    path == "/stream.mjpeg" ? StreamClient::Kind::mjpeg
                                            : StreamClient::Kind::snapshot,
                    *view);
    }
    refuse(request, 404, "Not Found", "no such page");
  }

  // Whether the request's Host names this machine's loopback.
  static bool local_host(evhttp_request *request) {
    const char *host = evhttp_find_header(evhttp_request_get_input_headers(request), "Host");
    if (host == nullptr)
      return true; // HTTP/1.0: no browser sends one without it
    std::string_view name(host);
    if (name.starts_with("[")) {
      name = name.substr(1, name.find(']') == std::string_view::npos ? 0 : name.find(']') - 1);
    } else if (const std::size_t colon = name.rfind(':'); colon != std::string_view::npos) {
      name = name.substr(0, colon);
    }
    return name == "localhost" || name == "::1" || name.starts_with("127.");
  }

  void refuse(evhttp_request *request, int status, const char *reason, const std::string &why) {
    ++stats_.refused_requests;
    error(request, status, reason, why);
  }

  static std::optional<View> view_of(const evhttp_uri *uri) {
    const char *query = uri != nullptr ? evhttp_uri_get_query(uri) : nullptr;
    if (query == nullptr)
      return View::composite;
    evkeyvalq fields{};
    if (evhttp_parse_query_str(query, &fields) != 0)
      return std::nullopt;
    const char *view = evhttp_find_header(&fields, "view");
    std::optional<View> out;
    if (view == nullptr || std::strcmp(view, "composite") == 0)
      out = View::composite;
    else if (std::strcmp(view, "camera") == 0)
      out = View::camera;
    else if (std::strcmp(view, "region") == 0)
      out = View::region;
    evhttp_clear_headers(&fields);
    return out;
  }

  void stream(evhttp_request *request, StreamClient::Kind kind, View view) {
    if (int(clients_.size()) >= kMaxStreamClients)
      return refuse(request, 503, "Service Unavailable", "too many preview and event streams open");
    StreamClient &client = clients_.emplace_back();
    client.server = this;
    client.request = request;
    client.kind = kind;
    client.view = view;
    client.due_ns = kind == StreamClient::Kind::snapshot ? now_ns() + kSnapshotWaitNs : 0;
    evhttp_connection_set_closecb(evhttp_request_get_connection(request), &HttpServer::on_close,
                                  &client);
    if (kind != StreamClient::Kind::events)
      host_.watch(view, +1);
    if (kind == StreamClient::Kind::snapshot)
      return; // answered once its frame is there
    evkeyvalq *headers = evhttp_request_get_output_headers(request);
    evhttp_add_header(headers, "Cache-Control", "no-store");
    evhttp_add_header(headers, "X-Content-Type-Options", "nosniff");
    if (kind == StreamClient::Kind::mjpeg) {
      evhttp_add_header(headers, "Content-Type",
                        (std::string("multipart/x-mixed-replace;boundary=") + kBoundary).c_str());
    } else {
      evhttp_add_header(headers, "Content-Type", "text/event-stream");
    }
    evhttp_send_reply_start(request, 200, "OK");
  }

  // The client's connection is gone. A stream libevent had not seen
  // finished is taken off the connection, left to its user to free
  // (evhttp_connection_incoming_fail); one still on it is freed with it.
  void closed(StreamClient *client) {
    for (auto it = clients_.begin(); it != clients_.end(); ++it)
      if (&*it == client) {
        if (client->kind != StreamClient::Kind::events)
          host_.watch(client->view, -1);
        if (evhttp_request_get_connection(client->request) == nullptr)
          evhttp_request_free(client->request);
        clients_.erase(it);
        return;
      }
  }

  // The server lets go of a client it has finished with.
  void forget(StreamClient &client) {
    evhttp_connection_set_closecb(evhttp_request_get_connection(client.request), nullptr, nullptr);
    if (client.kind != StreamClient::Kind::events)
      host_.watch(client.view, -1);
  }

  // The JPEG of `view`'s newest preview, encoded once per frame.
  struct Encoded {
    std::uint64_t frame = ~std::uint64_t(0);
    std::vector<unsigned char> jpeg;
  };
  const Encoded *encoded(View view) {
    const PreviewImage &image = host_.preview(view);
    if (!image.valid)
      return nullptr;
    Encoded &cache = encoded_[int(view)];
    if (cache.frame != image.frame || cache.jpeg.empty()) {
      const std::int64_t start = now_ns();
      const std::span<const unsigned char> jpeg = encoder_.encode(image);
      if (jpeg.empty())
        return nullptr;
      stats_.jpeg_seconds += double(now_ns() - start) * 1e-9;
      ++stats_.jpeg_frames;
      cache.jpeg.assign(jpeg.begin(), jpeg.end());
      cache.frame = image.frame;
    }
    return &cache;
  }

  void tick() {
    if (stop_) {
      event_base_loopbreak(base_);
      return;
    }
    const std::int64_t now = now_ns();
    for (auto it = clients_.begin(); it != clients_.end();) {
      StreamClient &client = *it;
      if (client.writing) {
        ++it;
        continue;
      }
      if (client.kind == StreamClient::Kind::events) {
        if (now >= client.due_ns) {
          client.due_ns = now + kEventIntervalNs;
          const std::string event = "data: " + host_.state_json(stats()) + "\n\n";
          send_chunk(client, event.data(), event.size());
        }
        ++it;
        continue;
      }
      const Encoded *frame = encoded(client.view);
      const bool fresh = frame != nullptr && frame->frame != client.last_frame;
      if (client.kind == StreamClient::Kind::snapshot) {
        if (fresh || now >= client.due_ns) {
          forget(client);
          if (fresh) {
            evkeyvalq *headers = evhttp_request_get_output_headers(client.request);
            evhttp_add_header(headers, "X-Frame", std::to_string(frame->frame).c_str());
            reply(client.request, 200, "OK", "image/jpeg",
                  {reinterpret_cast<const char *>(frame->jpeg.data()), frame->jpeg.size()});
            ++stats_.preview_frames;
          } else {
            refuse(client.request, 503, "Service Unavailable", "no frame came to show");
          }
          it = clients_.erase(it);
          continue;
        }
        ++it;
        continue;
      }
      if (fresh) {
        char head[160];
        const int n =
            std::snprintf(head, sizeof head,
                          "--%s\r\nContent-Type: image/jpeg\r\nContent-Length: %zu\r\n"
                          "X-Frame: %llu\r\n\r\n",
                          kBoundary, frame->jpeg.size(), (unsigned long long)frame->frame);
        evbuffer *buffer = evbuffer_new();
        evbuffer_add(buffer, head, std::size_t(n));
        evbuffer_add(buffer, frame->jpeg.data(), frame->jpeg.size());
        evbuffer_add(buffer, "\r\n", 2);
        client.writing = true;
        client.last_frame = frame->frame;
        evhttp_send_reply_chunk_with_cb(client.request, buffer, &HttpServer::on_written, &client);
        evbuffer_free(buffer);
        ++stats_.preview_frames;
      }
      ++it;
    }
  }

  void send_chunk(StreamClient &client, const char *data, std::size_t size) {
    evbuffer *buffer = evbuffer_new();
    evbuffer_add(buffer, data, size);
    client.writing = true;
    evhttp_send_reply_chunk_with_cb(client.request, buffer, &HttpServer::on_written, &client);
    evbuffer_free(buffer);
  }

  HttpStats stats() const {
    HttpStats s = stats_;
    s.stream_clients = int(clients_.size());
    return s;
  }

  web_module::Host &host_;
  HttpAuth auth_;
  event_base *base_ = nullptr;
  evhttp *http_ = nullptr;
  event *tick_ = nullptr;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::string url_;
  HttpStats stats_;
  std::list<StreamClient> clients_; // stable addresses: libevent holds them
  JpegEncoder encoder_;
  Encoded encoded_[kViews];
};

class EventModule final : public web_module::Module {
public:
  std::unique_ptr<web_module::Server> start(const web_module::ServerConfig &config,
                                            web_module::Host &host, std::string &error) override {
    try {
      auto server = std::make_unique<HttpServer>(config, host);
      if (!server->start(config, error))
        return nullptr;
      return server;
    } catch (const std::exception &e) {
      error = e.what();
      return nullptr;
    }
  }
  bool hash_password(const std::string &password, std::string &hash, std::string &error) override {
    hash = web::hash_password(password, error);
    return !hash.empty();
  }
};

} // namespace
} // namespace camhead::pipeline::web

extern "C" __attribute__((visibility("default"))) camhead::pipeline::web_module::Module *
camhead_web_module(int abi_version) {
  static camhead::pipeline::web::EventModule module;
  return abi_version == camhead::pipeline::web_module::kAbiVersion ? &module : nullptr;
}
