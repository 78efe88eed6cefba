#include "chart_png.h"

#include "camhead/renderer/image.h"
#include "camhead/renderer/image_io.h"

namespace camhead::cli::chart {

void write_png(const std::filesystem::path &png, const Canvas &canvas) {
  renderer::Image image(canvas.width, canvas.height, 3);
  for (std::size_t i = 0; i < canvas.rgb.size(); ++i)
    image.data[i] = renderer::srgb_to_linear(canvas.rgb[i] / 255.0f);
  renderer::write_image(png, image);
}

} // namespace camhead::cli::chart
