// libFuzzer target for the lens-trace reader (hal/lens/trace/lens_trace.h):
// any text must be refused with a TraceError or read into readings in time
// order that the writer writes back and the reader reads back identically.
#include <cstddef>
#include <cstdint>

#include "camhead/hal/lens/trace/lens_trace.h"
#include "fuzz_check.h"

using camhead::fuzz::check;
namespace lens = camhead::hal::lens;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  lens::LensTrace trace;
  try {
    trace = lens::parse_lens_trace(camhead::fuzz::text_of(data, size), "fuzz_trace.csv");
  } catch (const lens::TraceError &) {
    return 0;
  }
  for (std::size_t i = 0; i < trace.readings.size(); ++i)
    check(trace.readings[i].t_ns >= 0 &&
          (i == 0 || trace.readings[i].t_ns >= trace.readings[i - 1].t_ns));
  const lens::LensTrace again =
      lens::parse_lens_trace(lens::format_lens_trace(trace.readings), "again.csv");
  check(again.readings == trace.readings);
  return 0;
}
