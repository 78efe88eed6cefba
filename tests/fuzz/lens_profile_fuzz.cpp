// libFuzzer target for the lens-profile reader (lens_control/lens_profile.h):
// any text must be refused with a ProfileError or give a profile whose every
// lookup, anywhere in the encoders' range, is a positive number (only
// focus may be infinite). Any other exception is a finding: nothing a file
// says may reach an internal invariant (docs/input-errors.md).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "camhead/lens_control/lens_profile.h"
#include "fuzz_check.h"

using camhead::fuzz::check;
using camhead::lens_control::LensProfile;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  try {
    const LensProfile profile =
        LensProfile::parse(camhead::fuzz::text_of(data, size), "fuzz_profile.json");
    constexpr double kCounts[] = {
        std::numeric_limits<std::int32_t>::min(), -1.0, 0.0, 0.5, 1000.0, 65535.0,
        std::numeric_limits<std::int32_t>::max()};
    const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
    for (const double zoom : kCounts) {
      check(positive(profile.f_number(zoom).value));
      check(positive(profile.focal_length_mm(zoom).value));
      check(std::isfinite(profile.entrance_pupil_offset_mm(zoom).value));
      for (const double focus : kCounts) {
        const double d = profile.focus_distance_m(zoom, focus).value;
        check(!std::isnan(d) && d > 0.0);
        check(positive(profile.projection_focal_length_mm(zoom, focus).value));
      }
    }
  } catch (const camhead::lens_control::ProfileError &) {
  }
  return 0;
}
