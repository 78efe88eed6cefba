// The fake kernel behind libgpiod 1.6; see fake_gpiod.h for what it models.
// Only the functions src/gpiod_edge_source.cpp calls are defined here.
#include "fake_gpiod.h"

#include <algorithm>
#include <cerrno>
#include <deque>
#include <map>
#include <memory>
#include <set>
#include <vector>

#include <dlfcn.h>
#include <gpiod.h>

#include "gpiod_library.h"

namespace {

struct LineState {
  bool level = false; // physical
  bool requested = false;
  const gpiod_chip *owner = nullptr; // the handle that requested it; null: hold_line()
  std::string consumer;
  int flags = 0;
  std::deque<gpiod_line_event> queue;
  std::uint64_t dropped = 0;
};

struct ChipState {
  std::string name, label;
  std::vector<LineState> lines;
  bool removed = false;
};

std::map<std::string, std::shared_ptr<ChipState>> &chips() {
  static std::map<std::string, std::shared_ptr<ChipState>> all;
  return all;
}

} // namespace

// The opaque libgpiod types, as the fake has them.
struct gpiod_line {
  gpiod_chip *chip;
  unsigned offset;
};
struct gpiod_chip {
  std::shared_ptr<ChipState> state;
  std::vector<std::unique_ptr<gpiod_line>> lines;
};

namespace {

std::set<const gpiod_chip *> &fake_chips() {
  static std::set<const gpiod_chip *> all;
  return all;
}
std::set<const gpiod_line *> &fake_lines() {
  static std::set<const gpiod_line *> all;
  return all;
}

bool is_fake(const gpiod_chip *chip) {
  return fake_chips().count(chip) != 0;
}
bool is_fake(const gpiod_line *line) {
  return fake_lines().count(line) != 0;
}

LineState &state_of(gpiod_line *line) {
  return line->chip->state->lines[line->offset];
}

// The real libgpiod function `name`, for handles that are not fakes.
template <typename Fn> Fn *real(const char *name) {
  void *fn = dlsym(RTLD_NEXT, name);
  if (fn == nullptr) {
    static void *lib = dlopen("libgpiod.so.2", RTLD_NOW | RTLD_GLOBAL);
    fn = lib != nullptr ? dlsym(lib, name) : nullptr;
  }
  return reinterpret_cast<Fn *>(fn);
}

LineState &line_state(const std::string &chip, unsigned offset) {
  return chips().at(chip)->lines.at(offset);
}

} // namespace

namespace camhead::test::fake_gpiod {

void reset() {
  chips().clear();
}

void add_chip(const std::string &name, const std::string &label, unsigned num_lines) {
  auto chip = std::make_shared<ChipState>();
  chip->name = name;
  chip->label = label;
  chip->lines.resize(num_lines);
  chips()[name] = chip;
}

void remove_chip(const std::string &name) {
  chips().at(name)->removed = true;
  chips().erase(name);
}

void set_level(const std::string &chip, unsigned offset, bool level, std::int64_t t_ns) {
  LineState &l = line_state(chip, offset);
  l.level = level;
  if (!l.requested) {
    return;
  }
  if (l.queue.size() == 16) {
    ++l.dropped; // the v1 kfifo is full: the kernel drops the event
    return;
  }
  const bool logical = level != ((l.flags & GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW) != 0);
  gpiod_line_event e{};
  e.ts.tv_sec = static_cast<time_t>(t_ns / 1'000'000'000);
  e.ts.tv_nsec = static_cast<long>(t_ns % 1'000'000'000);
  e.event_type = logical ? GPIOD_LINE_EVENT_RISING_EDGE : GPIOD_LINE_EVENT_FALLING_EDGE;
  l.queue.push_back(e);
}

void hold_line(const std::string &chip, unsigned offset, const std::string &consumer) {
  LineState &l = line_state(chip, offset);
  l.requested = true;
  l.consumer = consumer;
}

LineInfo line_info(const std::string &chip, unsigned offset) {
  const LineState &l = line_state(chip, offset);
  return LineInfo{l.requested, l.consumer, l.flags, l.dropped};
}

int open_handles() {
  return static_cast<int>(fake_chips().size());
}

} // namespace camhead::test::fake_gpiod

// --- libgpiod 1.6 entry points ------------------------------------------------

extern "C" {

gpiod_chip *gpiod_chip_open_lookup(const char *descr) {
  for (const auto &[name, state] : chips()) {
    if (name == descr || state->label == descr) {
      auto *chip = new gpiod_chip{state, {}};
      chip->lines.resize(state->lines.size());
      fake_chips().insert(chip);
      return chip;
    }
  }
  return real<decltype(gpiod_chip_open_lookup)>("gpiod_chip_open_lookup")(descr);
}

void gpiod_chip_close(gpiod_chip *chip) {
  if (!is_fake(chip)) {
    real<decltype(gpiod_chip_close)>("gpiod_chip_close")(chip);
    return;
  }
  for (const auto &line : chip->lines) {
    if (line) {
      LineState &l = state_of(line.get());
      if (l.requested && l.owner == chip) { // releases what this handle requested
        l.requested = false;
        l.owner = nullptr;
        l.queue.clear();
      }
      fake_lines().erase(line.get());
    }
  }
  fake_chips().erase(chip);
  delete chip;
}

const char *gpiod_chip_name(gpiod_chip *chip) {
  if (!is_fake(chip)) {
    return real<decltype(gpiod_chip_name)>("gpiod_chip_name")(chip);
  }
  return chip->state->name.c_str();
}

unsigned int gpiod_chip_num_lines(gpiod_chip *chip) {
  if (!is_fake(chip)) {
    return real<decltype(gpiod_chip_num_lines)>("gpiod_chip_num_lines")(chip);
  }
  return static_cast<unsigned>(chip->state->lines.size());
}

gpiod_line *gpiod_chip_get_line(gpiod_chip *chip, unsigned int offset) {
  if (!is_fake(chip)) {
    return real<decltype(gpiod_chip_get_line)>("gpiod_chip_get_line")(chip, offset);
  }
  if (offset >= chip->lines.size()) {
    errno = EINVAL;
    return nullptr;
  }
  if (!chip->lines[offset]) {
    chip->lines[offset] = std::make_unique<gpiod_line>(gpiod_line{chip, offset});
    fake_lines().insert(chip->lines[offset].get());
  }
  return chip->lines[offset].get();
}

int gpiod_line_request_both_edges_events_flags(gpiod_line *line, const char *consumer, int flags) {
  if (!is_fake(line)) {
    return real<decltype(gpiod_line_request_both_edges_events_flags)>(
        "gpiod_line_request_both_edges_events_flags")(line, consumer, flags);
  }
  LineState &l = state_of(line);
  if (l.requested) {
    errno = EBUSY;
    return -1;
  }
  l.requested = true;
  l.owner = line->chip;
  l.consumer = consumer;
  l.flags = flags;
  return 0;
}

int gpiod_line_update(gpiod_line *line) {
  if (!is_fake(line)) {
    return real<decltype(gpiod_line_update)>("gpiod_line_update")(line);
  }
  return 0;
}

const char *gpiod_line_consumer(gpiod_line *line) {
  if (!is_fake(line)) {
    return real<decltype(gpiod_line_consumer)>("gpiod_line_consumer")(line);
  }
  const LineState &l = state_of(line);
  return l.requested ? l.consumer.c_str() : nullptr;
}

int gpiod_line_get_value(gpiod_line *line) {
  if (!is_fake(line)) {
    return real<decltype(gpiod_line_get_value)>("gpiod_line_get_value")(line);
  }
  if (line->chip->state->removed) {
    errno = ENODEV;
    return -1;
  }
  const LineState &l = state_of(line);
  return l.level != ((l.flags & GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW) != 0) ? 1 : 0;
}

int gpiod_line_event_wait_bulk(gpiod_line_bulk *bulk, const timespec *timeout,
                               gpiod_line_bulk *event_bulk) {
  if (gpiod_line_bulk_num_lines(bulk) == 0 || !is_fake(gpiod_line_bulk_get_line(bulk, 0))) {
    return real<decltype(gpiod_line_event_wait_bulk)>("gpiod_line_event_wait_bulk")(bulk, timeout,
                                                                                    event_bulk);
  }
  // Nothing happens while a test waits, so a wait without events times out
  // at once. A removed chip's lines poll as ready (EPOLLHUP | EPOLLERR).
  gpiod_line_bulk_init(event_bulk);
  for (unsigned i = 0; i < gpiod_line_bulk_num_lines(bulk); ++i) {
    gpiod_line *line = gpiod_line_bulk_get_line(bulk, i);
    if (line->chip->state->removed || !state_of(line).queue.empty()) {
      gpiod_line_bulk_add(event_bulk, line);
    }
  }
  return gpiod_line_bulk_num_lines(event_bulk) > 0 ? 1 : 0;
}

int gpiod_line_event_read_multiple(gpiod_line *line, gpiod_line_event *events,
                                   unsigned int num_events) {
  if (!is_fake(line)) {
    return real<decltype(gpiod_line_event_read_multiple)>("gpiod_line_event_read_multiple")(
        line, events, num_events);
  }
  if (line->chip->state->removed) {
    errno = ENODEV;
    return -1;
  }
  std::deque<gpiod_line_event> &q = state_of(line).queue;
  const auto n = static_cast<unsigned>(std::min<std::size_t>(num_events, q.size()));
  std::copy_n(q.begin(), n, events);
  q.erase(q.begin(), q.begin() + n);
  return static_cast<int>(n);
}

} // extern "C"

// --- The backend's table, filled from the link ---------------------------------
// The backend calls libgpiod through detail::gpiod() (src/gpiod_library.h),
// which camhead fills by dlopen. Defined here, the table holds the functions
// above instead: this binary's definitions take the place of the library's
// gpiod_library.cpp, which the linker then leaves out.
namespace camhead::hal::lens::gpio::detail {

const std::string &gpiod_load_error() {
  static const std::string none;
  return none;
}

const GpiodFunctions &gpiod() {
#define CAMHEAD_GPIOD_LINKED(name) .name = &::gpiod_##name,
  static const GpiodFunctions linked{CAMHEAD_GPIOD_FUNCTIONS(CAMHEAD_GPIOD_LINKED)};
#undef CAMHEAD_GPIOD_LINKED
  return linked;
}

} // namespace camhead::hal::lens::gpio::detail
