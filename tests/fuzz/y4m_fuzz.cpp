// libFuzzer target for the file camera's Y4M reader (hal/camera/file): the
// input is the whole file, held in a memfd so that the reader runs as it
// does on disk (it refuses anything but a regular file). The file must be
// refused with a FileCameraError or give frames, each read whole or ended
// with an error message; rewinding (as looping does) must give the first
// frame again.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <sys/mman.h>
#include <unistd.h>

#include "camhead/base/video_format.h"
#include "frame_reader.h"
#include "fuzz_check.h"

namespace {

using camhead::fuzz::check;
namespace camera = camhead::hal::camera;

struct MemoryFile {
  int fd = ::memfd_create("y4m_fuzz", MFD_CLOEXEC);
  ~MemoryFile() { ::close(fd); }
};

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  const MemoryFile file;
  check(file.fd >= 0);
  for (std::size_t done = 0; done < size;) {
    const ssize_t n = ::write(file.fd, data + done, size - done);
    check(n > 0);
    done += std::size_t(n);
  }
  const std::string path = "/proc/self/fd/" + std::to_string(file.fd);
  std::unique_ptr<camera::FrameReader> reader;
  try {
    // Whether the caller gives a rate changes what a header may omit.
    reader = camera::open_y4m_reader(path, size % 2 == 0);
  } catch (const camera::FileCameraError &) {
    return 0;
  }
  std::vector<std::uint8_t> first(camhead::base::frame_bytes(reader->format()));
  std::vector<std::uint8_t> frame(first.size());
  std::string error;
  using Read = camera::FrameReader::Read;
  for (int i = 0; i < 4; ++i) {
    const Read r = reader->read(i == 0 ? first : frame, error);
    check((r == Read::error) == !error.empty());
    if (r == Read::error)
      return 0; // the reader is not used again after an error
    // The reader has checked frame 0 whole before it was made.
    check(r == Read::frame || i > 0);
    if (r == Read::end)
      break;
  }
  check(reader->rewind(error));
  check(reader->read(frame, error) == camera::FrameReader::Read::frame);
  check(frame == first);
  return 0;
}
