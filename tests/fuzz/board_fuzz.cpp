// libFuzzer target for the board-file reader (pipeline/board.h): any text
// must be refused with a BoardError or parsed; any other exception is a
// finding. Paths inside a board are only stored, never opened, here.
#include <cstddef>
#include <cstdint>

#include "board.h"
#include "fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  try {
    (void)camhead::pipeline::parse_board(camhead::fuzz::text_of(data, size),
                                         "/nonexistent/fuzz_board.json");
  } catch (const camhead::pipeline::BoardError &) {
  }
  return 0;
}
