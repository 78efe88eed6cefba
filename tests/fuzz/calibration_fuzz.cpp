// libFuzzer target for the calibration measurements reader
// (lens_control/calibration.h), followed through what `camhead calibrate`
// does with them: any text must be refused with a CalibrationError, or fit
// (or be refused by the fit with a CalibrationError) into a profile that the
// profile reader accepts. A profile calibrate writes and camhead cannot read
// is a finding, as is any other exception.
#include <cstddef>
#include <cstdint>
#include <string>

#include "camhead/lens_control/calibration.h"
#include "camhead/lens_control/lens_profile.h"
#include "fuzz_check.h"

namespace lc = camhead::lens_control;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  std::string json;
  lc::CalibrationOptions options;
  options.name = "fuzz";
  try {
    const lc::MeasurementSet set =
        lc::parse_measurements(camhead::fuzz::text_of(data, size), "fuzz_measurements.csv");
    options.prime = size > 0 && (data[0] & 1) != 0;
    json = lc::profile_json(lc::fit_calibration(set, options), options);
  } catch (const lc::CalibrationError &) {
    return 0;
  }
  try {
    (void)lc::LensProfile::parse(json, "fitted.json");
  } catch (const lc::ProfileError &) {
    camhead::fuzz::check(false);
  }
  return 0;
}
