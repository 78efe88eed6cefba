// What `camhead run` tells systemd as it runs (service_notifier.h), from
// its status thread: READY=1 once the first frame is out (a composite or
// the placeholder), WATCHDOG=1 at half the watchdog's timeout while the
// output advances (output_watchdog.h), the status line as STATUS=, and
// STOPPING=1 at the end. Without a service manager every call does nothing.
//
// Thread safety: one thread (the run's status thread) calls every member;
// the counters are the run's atomics.
#pragma once

#include <cstdint>
#include <string>

#include "run/run_counters.h"
#include "service/output_watchdog.h"
#include "service/service_notifier.h"

namespace camhead::pipeline {

class ServiceHeartbeat {
public:
  // `service` null or inactive: nothing is sent.
  ServiceHeartbeat(const ServiceNotifier *service, const RunCounters &counters);

  // Often (every few tens of ms): READY=1 and WATCHDOG=1 as they fall due.
  void tick(std::int64_t now_ns);
  // Each status line.
  void status(const std::string &line) const;
  void stopping() const;

private:
  [[nodiscard]] OutputProgress progress() const;

  const ServiceNotifier *service_;
  const RunCounters &counters_;
  std::int64_t watchdog_ns_ = 0; // between WATCHDOG=1s; 0: no watchdog
  bool ready_ = false;
  OutputProgress watched_;
  std::int64_t watched_ns_ = 0;
};

} // namespace camhead::pipeline
