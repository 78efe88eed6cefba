#include "calibration_marks.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <system_error>

namespace camhead::pipeline::web {

std::optional<MarkAxis> parse_mark_axis(std::string_view name) {
  if (name == "focus")
    return MarkAxis::focus;
  if (name == "iris")
    return MarkAxis::iris;
  if (name == "zoom")
    return MarkAxis::zoom;
  return std::nullopt;
}

std::string append_mark(const std::filesystem::path &file, const std::string &board, MarkAxis axis,
                        std::int32_t counts, double value) {
  std::error_code error;
  if (file.has_parent_path())
    std::filesystem::create_directories(file.parent_path(), error);
  if (error)
    return file.parent_path().string() + ": " + error.message();
  const bool fresh = !std::filesystem::exists(file, error);
  std::FILE *out = std::fopen(file.c_str(), "a");
  if (out == nullptr)
    return file.string() + ": " + std::strerror(errno);
  if (fresh) {
    const std::time_t now = std::time(nullptr);
    std::tm local{};
    localtime_r(&now, &local);
    char date[32];
    std::strftime(date, sizeof date, "%Y-%m-%d %H:%M", &local);
    std::fprintf(out,
                 "# Calibration marks of board %s from the operator page, begun %s.\n"
                 "# camhead calibrate %s --name \"LENS\" -o LENS.json\n"
                 "axis,counts,distance_m,f_number,t_stop,focal_length_mm\n",
                 board.c_str(), date, file.filename().c_str());
  }
  switch (axis) {
  case MarkAxis::focus:
    std::fprintf(out, "focus,%d,%.6g,,,\n", counts, value);
    break;
  case MarkAxis::iris:
    std::fprintf(out, "iris,%d,,%.6g,,\n", counts, value);
    break;
  case MarkAxis::zoom:
    std::fprintf(out, "zoom,%d,,,,%.6g\n", counts, value);
    break;
  }
  const bool written = std::ferror(out) == 0;
  if (std::fclose(out) != 0 || !written)
    return file.string() + ": the row was not written whole (a full disk?)";
  return {};
}

} // namespace camhead::pipeline::web
