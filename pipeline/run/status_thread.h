// The run's status thread (the calling thread of run_pipeline(), while the
// frame loop's threads run): the status line a second (run_status.h), a
// reload's outcome as a line of its own, and what systemd hears
// (service_heartbeat.h: WATCHDOG=1 while output advances, STATUS= with the
// line and a refused reload's reason until one is taken).
#pragma once

#include <cstdint>
#include <functional>

#include "run_counters.h"
#include "run_status.h"
#include "service/service_notifier.h"
#include "setup_reloader.h"

namespace camhead::pipeline {

// Runs until `done` says the run is over (asked every 20 ms, so that a run
// ends as soon as its last frame is out); then STOPPING=1 and the line
// ended. `status` null: no status line (the heartbeat still runs);
// `service` and `reloader` null: none. `start_ns`: when the run started.
void run_status_thread(RunStatus *status, const ServiceNotifier *service,
                       const RunCounters &counters, SetupReloader *reloader, std::int64_t start_ns,
                       const std::function<bool()> &done);

} // namespace camhead::pipeline
