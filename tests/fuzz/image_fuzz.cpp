// libFuzzer target for the image readers (renderer/image_io.h), built twice:
// IMAGE_EXTENSION picks EXR (tinyexr) or PNG (libpng, base/png_reader.h,
// with CRCs unchecked in this build). Any bytes must be refused with an
// ImageError or decoded into a whole RGB image; any other exception, crash,
// undefined behaviour or allocation past libFuzzer's -malloc_limit_mb is a
// finding. PNG bytes also go through the file camera's decoder
// (hal/video_file/png_frame.h), the other PNG reader.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "camhead/hal/video_file/png_frame.h"
#include "camhead/renderer/image_io.h"
#include "fuzz_check.h"

namespace {

using camhead::fuzz::check;
namespace video_file = camhead::hal::video_file;

constexpr bool kPng = std::string_view(IMAGE_EXTENSION) == ".png";

void decode_as_frame(std::span<const std::uint8_t> bytes) {
  std::string error;
  const auto size = video_file::png_size(bytes, error);
  // The file camera refuses frames over its largest video format first.
  if (!size || size->width < 1 || size->height < 1 ||
      std::size_t(size->width) * std::size_t(size->height) > (std::size_t(1) << 24))
    return;
  std::vector<std::uint8_t> rgb(std::size_t(size->width) * std::size_t(size->height) * 3);
  if (!video_file::decode_png_rgb(bytes, *size, rgb, error))
    check(!error.empty());
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  try {
    const camhead::renderer::Image image =
        camhead::renderer::decode_image(bytes, "fuzz" IMAGE_EXTENSION);
    check(image.width >= 1 && image.height >= 1 && image.channels == 3);
    check(image.data.size() == std::size_t(image.width) * std::size_t(image.height) * 3);
    if (kPng)
      for (const float v : image.data)
        check(v >= 0.0f && v <= 1.0f);
  } catch (const camhead::renderer::ImageError &) {
  }
  if (kPng)
    decode_as_frame(bytes);
  return 0;
}
