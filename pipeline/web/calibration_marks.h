// The operator page's calibration helper: the lens's encoder counts now,
// with the value the crew measured for them (a focus distance on the tape,
// the iris's f-number, the zoom's focal length), appended as a row of the
// measurements file `camhead calibrate` reads
// (lens_control/calibration.h: axis,counts,distance_m,f_number,t_stop,
// focal_length_mm). The page's thread writes it; the frame loop never sees
// it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace camhead::pipeline::web {

enum class MarkAxis { focus, iris, zoom };

// "focus", "iris", "zoom"; nothing for anything else.
[[nodiscard]] std::optional<MarkAxis> parse_mark_axis(std::string_view name);

// Appends `axis` at `counts` measured as `value` (metres, f-number or
// millimetres) to `file`, made with its header (naming `board`) when it
// is not there. The error, or "" when the row was written whole.
[[nodiscard]] std::string append_mark(const std::filesystem::path &file, const std::string &board,
                                      MarkAxis axis, std::int32_t counts, double value);

} // namespace camhead::pipeline::web
