#include "camera_views.h"

#include <algorithm>
#include <cstdio>
#include <span>
#include <string_view>
#include <system_error>
#include <vector>

#include "camhead/base/partial_file.h"
#include "camhead/hal/video_file/png_frame.h"

namespace camhead::pipeline::web {
namespace {

namespace fs = std::filesystem;

// view-NNN.png: NNN from 1.
std::optional<int> view_number(const fs::path &file) {
  const std::string name = file.filename().string();
  constexpr std::string_view prefix = "view-", suffix = ".png";
  if (name.size() <= prefix.size() + suffix.size() || name.rfind(prefix, 0) != 0 ||
      name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
    return std::nullopt;
  int number = 0;
  for (std::size_t i = prefix.size(); i < name.size() - suffix.size(); ++i) {
    if (name[i] < '0' || name[i] > '9' || number > 99'999)
      return std::nullopt;
    number = number * 10 + (name[i] - '0');
  }
  return number;
}

} // namespace

std::string save_camera_view(const fs::path &recordings, const LumaImage &luma,
                             const LensPlace &place, SavedView &saved) {
  if (!place.focus)
    return "the lens gives no focus counts now (not connected, or it sends calibrated values): "
           "`camhead calibrate camera` needs the focus the views were taken at";
  saved.at = "focus=" + std::to_string(*place.focus);
  std::string folder_name = "focus-" + std::to_string(*place.focus);
  if (place.zoom) {
    saved.at += ",zoom=" + std::to_string(*place.zoom);
    folder_name += "-zoom-" + std::to_string(*place.zoom);
  }
  const fs::path folder = fs::absolute(recordings / "camera-views" / folder_name);
  std::error_code error;
  fs::create_directories(folder, error);
  if (error)
    return folder.string() + ": cannot be made: " + error.message();

  // The next number after the highest there (of any kind of file), and
  // the views there now.
  int highest = 0, views = 0;
  for (const fs::directory_entry &entry : fs::directory_iterator(folder, error))
    if (const std::optional<int> n = view_number(entry.path())) {
      highest = std::max(highest, *n);
      views += entry.is_regular_file();
    }
  if (error)
    return folder.string() + ": cannot be read: " + error.message();
  char name[32];
  std::snprintf(name, sizeof name, "view-%03d.png", highest + 1);
  saved.file = folder / name;

  std::vector<std::uint8_t> png;
  const std::span<const std::uint8_t> rows(luma.data,
                                           std::size_t(luma.stride) * std::size_t(luma.height));
  if (!hal::video_file::encode_png_grey(rows, luma.width, luma.height, std::size_t(luma.stride),
                                        png))
    return saved.file.string() + ": the PNG could not be made (out of memory?)";
  std::string why;
  std::optional<base::PartialFile> file = base::PartialFile::create(saved.file, why);
  if (!file || !file->write(png, why) || !file->commit(true, why))
    return saved.file.string() + ": " + why;
  saved.views = views + 1;
  return {};
}

} // namespace camhead::pipeline::web
