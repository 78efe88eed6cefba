// PNG sequences for the file camera. The first frame fixes the size and is
// decoded once at open, so that a sequence that cannot start is refused
// there; later frames are checked against it from their header before they
// are decoded.
#include <algorithm>
#include <cctype>
#include <optional>
#include <system_error>
#include <vector>

#include "camhead/base/input_file.h"
#include "camhead/hal/video_file/frame_pattern.h"
#include "camhead/hal/video_file/png_frame.h"
#include "frame_reader.h"

namespace camhead::hal::camera {
namespace {

using video_file::FramePattern;

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

bool is_png_name(const std::filesystem::path &path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".png";
}

class PngSequenceReader final : public FrameReader {
public:
  PngSequenceReader(const std::filesystem::path &path, WantedSize wanted);

  base::VideoFormat format() const override { return format_; }
  std::int64_t native_interval_ns() const override { return 0; }
  Read read(std::span<std::uint8_t> frame, std::string &error) override;
  bool rewind(std::string &) override {
    index_ = 0;
    return true;
  }

private:
  // Empty past the end of a listed sequence.
  [[nodiscard]] std::filesystem::path frame_path(std::uint64_t index) const;
  void list_folder(const std::filesystem::path &folder);

  std::optional<FramePattern> pattern_;
  std::uint64_t first_number_ = 0;
  std::vector<std::filesystem::path> files_; // a folder or a single file
  base::VideoFormat format_;
  std::uint64_t index_ = 0;
  std::vector<std::uint8_t> bytes_;
};

PngSequenceReader::PngSequenceReader(const std::filesystem::path &path, WantedSize wanted) {
  const std::string text = path.string();
  std::error_code ec;
  if (FramePattern::is_pattern(text)) {
    std::string error;
    pattern_ = FramePattern::parse(text, error);
    if (!pattern_)
      throw FileCameraError(text + ": pattern: " + error);
    if (std::filesystem::exists(pattern_->path(0), ec))
      first_number_ = 0;
    else if (std::filesystem::exists(pattern_->path(1), ec))
      first_number_ = 1;
    else
      throw FileCameraError(text + ": frames: neither " + pattern_->path(0).string() + " nor " +
                            pattern_->path(1).string() + " exists");
  } else if (std::filesystem::is_directory(path, ec)) {
    list_folder(path);
  } else {
    files_.push_back(path);
  }

  const std::filesystem::path first = frame_path(0);
  std::string error;
  if (!base::read_input_file(first, video_file::kMaxPngFileBytes, bytes_, error))
    throw FileCameraError(first.string() + ": " + error);
  const auto size = video_file::png_size(bytes_, error);
  if (!size)
    throw FileCameraError(first.string() + ": " + error);
  format_.pixel = base::PixelFormat::rgb24;
  format_.width = size->width;
  format_.height = size->height;
  check_size(first.string(), size->width, size->height, wanted);
  const std::string reason = base::check_video_format(format_);
  if (!reason.empty())
    throw FileCameraError(first.string() + ": PNG header: " + reason);
  std::vector<std::uint8_t> pixels(base::frame_bytes(format_));
  if (!video_file::decode_png_rgb(bytes_, *size, pixels, error))
    throw FileCameraError(first.string() + ": " + error);
}

void PngSequenceReader::list_folder(const std::filesystem::path &folder) {
  std::error_code ec;
  for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end;
       it.increment(ec)) {
    std::error_code type_ec;
    if (it->is_regular_file(type_ec) && is_png_name(it->path()))
      files_.push_back(it->path());
  }
  if (ec)
    throw FileCameraError(folder.string() + ": folder: " + ec.message());
  if (files_.empty())
    throw FileCameraError(folder.string() + ": folder: no .png files");
  // By name, bytewise: "0010.png" after "0009.png", as zero-padded numbering
  // intends; unpadded numbers ("10.png" before "9.png") need a pattern.
  std::sort(files_.begin(), files_.end(),
            [](const auto &a, const auto &b) { return a.filename() < b.filename(); });
}

std::filesystem::path PngSequenceReader::frame_path(std::uint64_t index) const {
  if (pattern_)
    return pattern_->path(first_number_ + index);
  return index < files_.size() ? files_[index] : std::filesystem::path();
}

FrameReader::Read PngSequenceReader::read(std::span<std::uint8_t> frame, std::string &error) {
  const std::filesystem::path path = frame_path(index_);
  std::error_code ec;
  // A pattern's sequence ends at the first number that is missing.
  if (path.empty() || (pattern_ && !std::filesystem::exists(path, ec)))
    return Read::end;
  const std::string at = path.string() + ":frame " + std::to_string(index_) + ": ";
  if (!base::read_input_file(path, video_file::kMaxPngFileBytes, bytes_, error)) {
    error = at + error;
    return Read::error;
  }
  const auto size = video_file::png_size(bytes_, error);
  if (!size) {
    error = at + error;
    return Read::error;
  }
  if (size->width != format_.width || size->height != format_.height) {
    error = at + "size: " + size_text(size->width, size->height) + " differs from the first " +
            "frame's " + size_text(format_.width, format_.height);
    return Read::error;
  }
  if (!video_file::decode_png_rgb(bytes_, *size, frame, error)) {
    error = at + error;
    return Read::error;
  }
  ++index_;
  return Read::frame;
}

} // namespace

std::unique_ptr<FrameReader> open_png_sequence_reader(const std::filesystem::path &path,
                                                      WantedSize wanted) {
  return std::make_unique<PngSequenceReader>(path, wanted);
}

} // namespace camhead::hal::camera
