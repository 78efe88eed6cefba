#include "tracking/calibration_views.h"

#include <algorithm>
#include <fstream>
#include <span>

#include "camhead/base/png_reader.h"
#include "camhead/base/video_format.h"
#include "camhead/hal/video_file/y4m_header.h"
#include "camhead/hal/video_file/y4m_planes.h"
#include "tracking/luma.h"

namespace camhead::pipeline {
namespace {

namespace fs = std::filesystem;

// A picture larger than this is not a camera's.
constexpr std::uintmax_t kMostPngBytes = std::uintmax_t(256) << 20;
constexpr int kMostPixels = 1 << 26;

[[noreturn]] void fail(const fs::path &file, const std::string &why) {
  throw CalibrationViewError(file.string() + ": " + why);
}

CalibrationPicture read_png(const fs::path &file) {
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(file, ec);
  if (ec)
    fail(file, "cannot be read (" + ec.message() + ")");
  if (size > kMostPngBytes)
    fail(file, "over 256 MB, not a camera's picture");
  std::ifstream in(file, std::ios::binary);
  std::vector<std::uint8_t> bytes(size);
  if (!in.read(reinterpret_cast<char *>(bytes.data()), std::streamsize(size)))
    fail(file, "cannot be read");
  std::string error;
  const std::optional<base::PngInfo> info = base::read_png_info(bytes, error);
  if (!info)
    fail(file, error);
  if (info->width < 1 || info->height < 1 || std::int64_t(info->width) * info->height > kMostPixels)
    fail(file, "is " + std::to_string(info->width) + "x" + std::to_string(info->height) +
                   ", not a camera's picture size");
  std::vector<std::uint8_t> rgb(std::size_t(info->width) * std::size_t(info->height) * 3);
  if (!base::decode_png_rgb(bytes, *info, rgb, error))
    fail(file, error);
  CalibrationPicture picture{file.filename().string(), info->width, info->height, {}};
  picture.luma.resize(std::size_t(info->width) * std::size_t(info->height));
  const base::VideoFormat format{base::PixelFormat::rgb24, info->width, info->height};
  copy_luma(format, rgb, picture.luma);
  return picture;
}

void read_y4m(const fs::path &file, std::size_t most, std::vector<CalibrationPicture> &out) {
  std::ifstream in(file, std::ios::binary);
  if (!in)
    fail(file, "cannot be opened");
  std::string line;
  if (!std::getline(in, line) || line.size() > hal::video_file::kY4mMaxHeaderBytes)
    fail(file, "no Y4M header line");
  std::string error;
  const std::optional<hal::video_file::Y4mHeader> header =
      hal::video_file::parse_y4m_header(line, error);
  if (!header)
    fail(file, "Y4M header: " + error);
  const base::VideoFormat format = hal::video_file::y4m_video_format(*header);
  const std::size_t frame_bytes = hal::video_file::y4m_plane_bytes(format);
  const std::size_t luma_bytes = std::size_t(header->width) * std::size_t(header->height);
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(file, ec);
  if (ec)
    fail(file, "cannot be read (" + ec.message() + ")");
  // The frames, each a FRAME line and its planes, whole; then every k-th
  // read, so that at most `most` spread over the video.
  std::vector<std::streamoff> planes;
  for (;;) {
    if (!std::getline(in, line))
      break;
    if (line.rfind("FRAME", 0) != 0 || line.size() > hal::video_file::kY4mMaxFrameHeaderBytes)
      fail(file, "frame " + std::to_string(planes.size()) + ": no FRAME line");
    const std::streamoff at = in.tellg();
    if (at < 0 || std::uintmax_t(at) + frame_bytes > size)
      fail(file, "frame " + std::to_string(planes.size()) + " is cut short");
    planes.push_back(at);
    in.seekg(at + std::streamoff(frame_bytes));
  }
  if (planes.empty())
    fail(file, "no frame after the header");
  most = std::max<std::size_t>(most, 1);
  const std::size_t step = std::max<std::size_t>(1, (planes.size() + most - 1) / most);
  in.clear();
  for (std::size_t k = 0; k < planes.size(); k += step) {
    CalibrationPicture picture{file.filename().string() + " frame " + std::to_string(k),
                               header->width,
                               header->height,
                               {}};
    picture.luma.resize(luma_bytes); // the Y plane comes first
    picture.limited_range = luma_limited_range(format);
    in.seekg(planes[k]);
    if (!in.read(reinterpret_cast<char *>(picture.luma.data()), std::streamsize(luma_bytes)))
      fail(file, "frame " + std::to_string(k) + " cannot be read");
    out.push_back(std::move(picture));
  }
}

} // namespace

std::vector<CalibrationPicture> read_calibration_views(const std::vector<fs::path> &files,
                                                       std::size_t frames_per_video) {
  std::vector<CalibrationPicture> out;
  for (const fs::path &file : files) {
    if (fs::is_directory(file))
      fail(file, "is a folder; give the pictures in it (folder/*.png)");
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](char c) { return char(std::tolower(c)); });
    if (ext == ".png")
      out.push_back(read_png(file));
    else if (ext == ".y4m")
      read_y4m(file, frames_per_video, out);
    else
      fail(file, "not a .png picture or a .y4m video");
  }
  return out;
}

} // namespace camhead::pipeline
