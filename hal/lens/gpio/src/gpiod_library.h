// libgpiod 1.6, opened at run time (camhead/hal/shared_library.h): the
// functions the edge source calls, as a table typed from <gpiod.h>. Call
// gpiod().chip_name(chip) where a linked program would call
// gpiod_chip_name(chip). The gpiod_line_bulk_* helpers are inline in the
// header and stay direct calls.
//
// gpiod_library.cpp fills the table by dlopen; the backend's tests link
// libgpiod and a fake kernel instead and fill it from the link
// (tests/hal/lens/gpio/fake_gpiod.cpp), so define both functions below or
// neither.
//
// Thread safety: the first call of either function loads the library
// (a function-local static); after that, both from any thread.
#pragma once

#include <string>

#include <gpiod.h>

namespace camhead::hal::lens::gpio::detail {

// Each X(name) is gpiod_<name>.
#define CAMHEAD_GPIOD_FUNCTIONS(X)                                                                 \
  X(chip_close)                                                                                    \
  X(chip_get_line)                                                                                 \
  X(chip_name)                                                                                     \
  X(chip_num_lines)                                                                                \
  X(chip_open_lookup)                                                                              \
  X(line_consumer)                                                                                 \
  X(line_event_read_multiple)                                                                      \
  X(line_event_wait_bulk)                                                                          \
  X(line_get_value)                                                                                \
  X(line_request_both_edges_events_flags)                                                          \
  X(line_update)

struct GpiodFunctions {
#define CAMHEAD_GPIOD_POINTER(name) decltype(&::gpiod_##name) name = nullptr;
  CAMHEAD_GPIOD_FUNCTIONS(CAMHEAD_GPIOD_POINTER)
#undef CAMHEAD_GPIOD_POINTER
};

// "" once libgpiod.so.2 is open with every function above; otherwise why
// not, naming the file and its Debian package.
[[nodiscard]] const std::string &gpiod_load_error();

// The table. Only after gpiod_load_error() returned "": otherwise it aborts
// with that error (a caller that did not ask is a bug, not a user's problem).
[[nodiscard]] const GpiodFunctions &gpiod();

} // namespace camhead::hal::lens::gpio::detail
