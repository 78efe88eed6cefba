#include "test_support.h"

#include <cmath>
#include <fstream>
#include <stdexcept>

#include <unistd.h>

#include "camhead/renderer/cpu_tracer.h"
#include "camhead/renderer/gpu_tracer.h"

#include <gtest/gtest.h>

namespace camhead::test {

std::filesystem::path source_dir() {
  return CAMHEAD_SOURCE_DIR;
}
std::filesystem::path reference_dir() {
  return source_dir() / "tests" / "assets" / "reference";
}

bool have_vulkan() {
  static const bool present = [] {
    try {
      return !renderer::list_gpu_devices().empty();
    } catch (const std::exception &) {
      return false;
    }
  }();
  return present;
}

renderer::RenderResult render_gpu(const renderer::Scene &scene, int rpp) {
  // One tracer for the whole test binary: device creation is the slow part.
  static renderer::GpuTracer tracer;
  tracer.load(renderer::compile_scene(scene));
  return tracer.render(renderer::make_frame_params(scene, rpp));
}

bool have_hardware_gpu() {
  static const bool present = [] {
    try {
      for (const auto &device : renderer::list_gpu_devices()) {
        if (device.type == "discrete" || device.type == "integrated") {
          return true;
        }
      }
    } catch (const std::exception &) {
    }
    return false;
  }();
  return present;
}

renderer::RenderResult render_fastest(const renderer::Scene &scene, int rpp) {
  return have_hardware_gpu() ? render_gpu(scene, rpp) : render_cpu(scene, rpp);
}

renderer::RenderResult render_cpu(const renderer::Scene &scene, int rpp) {
  return renderer::render_cpu(renderer::compile_scene(scene),
                              renderer::make_frame_params(scene, rpp));
}

double rmse(const renderer::Image &a, const renderer::Image &b) {
  if (a.width != b.width || a.height != b.height || a.channels != b.channels) {
    throw std::invalid_argument("rmse: images differ in size");
  }
  double sum = 0.0;
  for (std::size_t i = 0; i < a.data.size(); ++i) {
    const double d = double(a.data[i]) - double(b.data[i]);
    sum += d * d;
  }
  return std::sqrt(sum / double(a.data.size()));
}

double log_log_slope(const std::vector<double> &x, const std::vector<double> &y) {
  const double n = double(x.size());
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += std::log(x[i]) / n;
    my += std::log(y[i]) / n;
  }
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (std::log(x[i]) - mx) * (std::log(y[i]) - my);
    sxx += (std::log(x[i]) - mx) * (std::log(x[i]) - mx);
  }
  return sxy / sxx;
}

double relative_rmse(const renderer::Image &reference, const renderer::Image &test) {
  double sum = 0.0;
  for (float v : reference.data) {
    sum += double(v) * v;
  }
  const double rms = std::sqrt(sum / double(reference.data.size()));
  return rmse(reference, test) / rms;
}

bool all_finite(const renderer::Image &image) {
  for (float v : image.data) {
    if (!std::isfinite(v)) {
      return false;
    }
  }
  return true;
}

bool all_layers_finite(const renderer::RenderResult &r) {
  return all_finite(r.composite) && all_finite(r.mixed) && all_finite(r.real) &&
         all_finite(r.mask) && all_finite(r.depth);
}

ScratchDir::ScratchDir() {
  const auto *info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = std::string("camhead_") + (info ? info->test_suite_name() : "test") + "_" +
                     (info ? info->name() : "") + "_" + std::to_string(::getpid());
  for (char &c : name) {
    c = (c == '/') ? '_' : c;
  }
  path_ = std::filesystem::temp_directory_path() / name;
  std::filesystem::create_directories(path_);
}

ScratchDir::~ScratchDir() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

std::filesystem::path ScratchDir::write(const std::string &name, const std::string &bytes) const {
  std::ofstream(path_ / name, std::ios::binary) << bytes;
  return path_ / name;
}

renderer::Scene downscaled(renderer::Scene scene, int divisor) {
  scene.render.width /= divisor;
  scene.render.height /= divisor;
  if (scene.plate) {
    renderer::Image small(scene.render.width, scene.render.height, 3);
    for (int y = 0; y < small.height; ++y) {
      for (int x = 0; x < small.width; ++x) {
        for (int c = 0; c < 3; ++c) {
          small.at(x, y)[c] = scene.plate->at(x * divisor, y * divisor)[c];
        }
      }
    }
    scene.plate = std::move(small);
  }
  return scene;
}

} // namespace camhead::test
