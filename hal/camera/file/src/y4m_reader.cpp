// Y4M files for the file camera: the header is checked at open, and so is the
// first frame (its FRAME line and that the file holds all its bytes), so
// that a file that cannot play at all is refused with a reason rather than
// ending at once.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <new>

#include <sys/stat.h>

#include "camhead/hal/video_file/y4m_header.h"
#include "camhead/hal/video_file/y4m_planes.h"
#include "frame_reader.h"

namespace camhead::hal::camera {
namespace {

using video_file::kY4mMaxFrameHeaderBytes;
using video_file::kY4mMaxHeaderBytes;

struct FileCloser {
  void operator()(std::FILE *file) const { std::fclose(file); }
};

enum class LineEnd { newline, end_of_file, too_long };

LineEnd read_line(std::FILE *file, std::size_t max, std::string &line) {
  line.clear();
  int c = 0;
  while ((c = std::getc(file)) != EOF) {
    if (c == '\n')
      return LineEnd::newline;
    if (line.size() == max)
      return LineEnd::too_long;
    line += static_cast<char>(c);
  }
  return LineEnd::end_of_file;
}

std::string printable(std::string_view text) {
  std::string out;
  for (const char c : text.substr(0, 16))
    out += (c >= 0x20 && c < 0x7f) ? c : '?';
  return out;
}

class Y4mReader final : public FrameReader {
public:
  Y4mReader(const std::filesystem::path &path, bool rate_given, WantedSize wanted);

  base::VideoFormat format() const override { return format_; }
  std::int64_t native_interval_ns() const override {
    return video_file::y4m_frame_interval_ns(header_.rate_num, header_.rate_den);
  }
  Read read(std::span<std::uint8_t> frame, std::string &error) override;
  bool rewind(std::string &error) override;

private:
  Read frame_header(std::string &error);
  [[nodiscard]] std::string at_frame() const {
    return file_ + ":frame " + std::to_string(index_) + ": ";
  }

  std::string file_;
  std::unique_ptr<std::FILE, FileCloser> stream_;
  video_file::Y4mHeader header_;
  base::VideoFormat format_;
  off_t data_start_ = 0;
  std::size_t plane_bytes_ = 0;
  std::unique_ptr<std::uint8_t[]> planes_;
  std::uint64_t index_ = 0; // frame number within the current pass
  std::string line_;
};

Y4mReader::Y4mReader(const std::filesystem::path &path, bool rate_given, WantedSize wanted)
    : file_(path.string()) {
  stream_.reset(std::fopen(path.c_str(), "rbe"));
  if (!stream_)
    throw FileCameraError(file_ + ": open: " + std::strerror(errno));
  struct stat st {};
  if (::fstat(::fileno(stream_.get()), &st) != 0)
    throw FileCameraError(file_ + ": open: " + std::strerror(errno));
  // A pipe could be played once, but neither checked at open nor looped.
  if (!S_ISREG(st.st_mode))
    throw FileCameraError(file_ + ": open: not a regular file");

  switch (read_line(stream_.get(), kY4mMaxHeaderBytes, line_)) {
  case LineEnd::newline:
    break;
  case LineEnd::end_of_file:
    throw FileCameraError(file_ + ": header: the file ends before the header's end of line");
  case LineEnd::too_long:
    throw FileCameraError(file_ + ": header: no end of line in the first " +
                          std::to_string(kY4mMaxHeaderBytes) + " bytes");
  }
  std::string error;
  const auto header = video_file::parse_y4m_header(line_, error);
  if (!header)
    throw FileCameraError(file_ + ": header: " + error);
  header_ = *header;
  if (!rate_given && header_.rate_num == 0)
    throw FileCameraError(file_ + ": header: F missing or 0:0, the frame rate is unknown; " +
                          "give the camera a rate (fps)");
  format_ = video_file::y4m_video_format(header_);
  check_size(file_, format_.width, format_.height, wanted);
  plane_bytes_ = video_file::y4m_plane_bytes(format_);
  data_start_ = ::ftello(stream_.get());

  // Frame 0, before allocating anything its size: a 16384 x 16384 header on
  // a tiny file is refused, not given a gigabyte.
  switch (frame_header(error)) {
  case Read::frame:
    break;
  case Read::end:
    throw FileCameraError(at_frame() + "missing: the file has no frames");
  case Read::error:
    throw FileCameraError(error);
  }
  const off_t left = st.st_size - ::ftello(stream_.get());
  if (left < 0 || static_cast<std::size_t>(left) < plane_bytes_)
    throw FileCameraError(at_frame() + "truncated: " + std::to_string(left) + " of " +
                          std::to_string(plane_bytes_) + " bytes");
  try {
    planes_.reset(new std::uint8_t[plane_bytes_]);
  } catch (const std::bad_alloc &) {
    throw FileCameraError(file_ + ": memory: cannot allocate " + std::to_string(plane_bytes_) +
                          " bytes for a frame");
  }
  if (!rewind(error))
    throw FileCameraError(error);
}

FrameReader::Read Y4mReader::frame_header(std::string &error) {
  const int first = std::getc(stream_.get());
  if (first == EOF) {
    if (!std::ferror(stream_.get()))
      return Read::end;
    error = at_frame() + "read: " + std::strerror(errno);
    return Read::error;
  }
  std::ungetc(first, stream_.get());
  switch (read_line(stream_.get(), kY4mMaxFrameHeaderBytes, line_)) {
  case LineEnd::newline:
    break;
  case LineEnd::end_of_file:
    error = at_frame() + (std::ferror(stream_.get())
                              ? std::string("read: ") + std::strerror(errno)
                              : std::string("truncated: the FRAME line has no end of line"));
    return Read::error;
  case LineEnd::too_long:
    error = at_frame() + "garbled: no end of line in the first " +
            std::to_string(kY4mMaxFrameHeaderBytes) + " bytes of the FRAME line";
    return Read::error;
  }
  // Frame parameters after "FRAME " are allowed and mean nothing to us.
  if (!line_.starts_with("FRAME") || (line_.size() > 5 && line_[5] != ' ')) {
    error = at_frame() + "garbled: '" + printable(line_) + "' where FRAME should be";
    return Read::error;
  }
  return Read::frame;
}

FrameReader::Read Y4mReader::read(std::span<std::uint8_t> frame, std::string &error) {
  const Read header = frame_header(error);
  if (header != Read::frame)
    return header;
  const std::size_t got = std::fread(planes_.get(), 1, plane_bytes_, stream_.get());
  if (got < plane_bytes_) {
    error =
        at_frame() + (std::ferror(stream_.get()) ? std::string("read: ") + std::strerror(errno)
                                                 : "truncated: " + std::to_string(got) + " of " +
                                                       std::to_string(plane_bytes_) + " bytes");
    return Read::error;
  }
  video_file::y4m_planes_to_frame({planes_.get(), plane_bytes_}, format_, frame);
  ++index_;
  return Read::frame;
}

bool Y4mReader::rewind(std::string &error) {
  std::clearerr(stream_.get());
  if (::fseeko(stream_.get(), data_start_, SEEK_SET) != 0) {
    error = file_ + ": rewind: " + std::strerror(errno);
    return false;
  }
  index_ = 0;
  return true;
}

} // namespace

std::unique_ptr<FrameReader> open_y4m_reader(const std::filesystem::path &path, bool rate_given,
                                             WantedSize wanted) {
  return std::make_unique<Y4mReader>(path, rate_given, wanted);
}

} // namespace camhead::hal::camera
