// See service_heartbeat.h.
#include "service_heartbeat.h"

#include <chrono>

namespace camhead::pipeline {

ServiceHeartbeat::ServiceHeartbeat(const ServiceNotifier *service, const RunCounters &counters)
    : service_(service != nullptr && service->active() ? service : nullptr), counters_(counters) {
  // Half systemd's timeout, as sd_watchdog_enabled(3) advises.
  if (service_ != nullptr && service_->watchdog_timeout())
    watchdog_ns_ =
        std::chrono::duration_cast<std::chrono::nanoseconds>(*service_->watchdog_timeout())
            .count() /
        2;
}

OutputProgress ServiceHeartbeat::progress() const {
  return {.composites = counters_.frames_out,
          .placeholders = counters_.placeholders,
          .camera_lost = counters_.camera_lost,
          .renderer_lost = counters_.renderer_lost};
}

void ServiceHeartbeat::tick(std::int64_t now_ns) {
  if (service_ == nullptr)
    return;
  if (!ready_) {
    if (counters_.frames_out + counters_.placeholders + counters_.repeats == 0)
      return;
    ready_ = service_->notify("READY=1");
    watched_ = progress();
    watched_ns_ = now_ns;
    return;
  }
  if (watchdog_ns_ == 0 || now_ns - watched_ns_ < watchdog_ns_)
    return;
  const OutputProgress now = progress();
  if (output_advanced(watched_, now))
    (void)service_->notify("WATCHDOG=1");
  watched_ = now;
  watched_ns_ = now_ns;
}

void ServiceHeartbeat::status(const std::string &line) const {
  if (service_ != nullptr)
    (void)service_->notify("STATUS=" + line);
}

void ServiceHeartbeat::stopping() const {
  if (service_ != nullptr)
    (void)service_->notify("STOPPING=1");
}

} // namespace camhead::pipeline
