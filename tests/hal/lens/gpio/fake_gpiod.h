// An in-process stand-in for the kernel behind libgpiod 1.6, so that the real
// backend (src/gpiod_edge_source.cpp, unchanged) can be tested without GPIO
// hardware: a link seam. fake_gpiod.cpp defines the libgpiod functions that
// the backend calls, and the backend's function table (src/gpiod_library.h)
// points at them instead of at a dlopen'ed libgpiod; every call on a handle
// that is not a fake one is forwarded to the real libgpiod (dlsym
// RTLD_NEXT, else dlopen), so tests that want the real library (a missing
// chip) still get it.
//
// What the fake models of the v1 uAPI: one event queue per line holding 16
// (further events are dropped, as the kernel does), rising/falling from the
// logical level (active-low applied), EBUSY for a line someone else holds,
// and a removed chip: its handles' waits report the lines ready and reads
// fail with ENODEV, and it cannot be opened until it is added again.
//
// Thread safety: none; tests drive it from the test thread only.
#pragma once

#include <cstdint>
#include <string>

namespace camhead::test::fake_gpiod {

// Drops every fake chip (handles still open keep their removed chip).
void reset();
void add_chip(const std::string &name, const std::string &label, unsigned num_lines);
// As when a gpio-sim chip is deleted under a running program.
void remove_chip(const std::string &name);

// The line's physical level changes; when the line is requested for events,
// an event stamped `t_ns` is queued.
void set_level(const std::string &chip, unsigned offset, bool level, std::int64_t t_ns);
// Another consumer holds the line.
void hold_line(const std::string &chip, unsigned offset, const std::string &consumer);

struct LineInfo {
  bool requested = false;
  std::string consumer;
  int flags = 0; // GPIOD_LINE_REQUEST_FLAG_*
  std::uint64_t dropped = 0;
};
[[nodiscard]] LineInfo line_info(const std::string &chip, unsigned offset);
// Fake chip handles opened and not yet closed.
[[nodiscard]] int open_handles();

} // namespace camhead::test::fake_gpiod
