// See status_thread.h.
#include "status_thread.h"

#include <chrono>
#include <optional>
#include <string>
#include <thread>

#include "camhead/base/monotonic_clock.h"
#include "service/service_heartbeat.h"

namespace camhead::pipeline {

void run_status_thread(RunStatus *status, const ServiceNotifier *service,
                       const RunCounters &counters, SetupReloader *reloader, std::int64_t start_ns,
                       const std::function<bool()> &done) {
  if (status != nullptr)
    status->start();
  ServiceHeartbeat heartbeat(service, counters);
  std::uint64_t last_in = 0, last_out = 0;
  std::int64_t last_ns = start_ns;
  std::string refused; // the last reload's refusal, until one is taken
  while (!done()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const std::int64_t now = base::monotonic_ns();
    heartbeat.tick(now);
    if (status != nullptr && reloader != nullptr)
      if (std::optional<std::string> note = reloader->take_note()) {
        // A refusal stays in systemd's status until a reload is taken:
        // `systemctl status` must show why the board on disk is not the
        // one running.
        refused = note->rfind("reload refused", 0) == 0 ? *note : std::string();
        status->note(*note);
      }
    if (status == nullptr || now - last_ns < 1'000'000'000)
      continue;
    const std::uint64_t in = counters.frames_in, out = counters.frames_out;
    status->second(now, double(now - last_ns) * 1e-9, in - last_in, out - last_out);
    heartbeat.status(refused.empty() ? status->last_line() : status->last_line() + "; " + refused);
    last_in = in;
    last_out = out;
    last_ns = now;
  }
  heartbeat.stopping();
  if (status != nullptr)
    status->end();
}

} // namespace camhead::pipeline
