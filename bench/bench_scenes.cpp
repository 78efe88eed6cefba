#include "bench_scenes.h"

#include <cstdlib>
#include <stdexcept>

#include "camhead/renderer/scene_loader.h"

namespace camhead::bench {
namespace {

namespace fs = std::filesystem;

fs::path dir_from(const char *env_name, const char *configured) {
  const char *env = std::getenv(env_name);
  return fs::path(env && *env ? env : configured);
}

const std::string kPrimarySuffix = "_primary";

} // namespace

fs::path source_dir() {
  return dir_from("CAMHEAD_SOURCE_DIR", CAMHEAD_SOURCE_DIR);
}

std::vector<BenchScene> bench_scenes() {
  const fs::path source = source_dir();
  const fs::path basic = source / "tests" / "assets" / "reference" / "ar_basic.json";
  const fs::path demo = source / "scenes" / "ar_demo.json";
  return {{"ar_basic", basic, false},
          {"ar_demo", demo, false},
          {"ar_basic" + kPrimarySuffix, basic, true},
          {"ar_demo" + kPrimarySuffix, demo, true}};
}

BenchScene find_bench_scene(const std::string &name_or_file) {
  for (const BenchScene &scene : bench_scenes()) {
    if (scene.name == name_or_file) {
      return scene;
    }
  }
  // Any other scene file; a "_primary" suffix on a file name is not parsed.
  if (!fs::exists(name_or_file)) {
    throw std::runtime_error("no scene named or at '" + name_or_file +
                             "' (names: ar_basic, ar_demo, ar_basic_primary, ar_demo_primary)");
  }
  return {fs::path(name_or_file).stem().string(), name_or_file, false};
}

renderer::Scene load_bench_scene(const BenchScene &scene, int width, int height) {
  renderer::Scene loaded = renderer::load_scene(scene.file);
  if (loaded.plate && (loaded.plate->width != width || loaded.plate->height != height)) {
    loaded.plate.reset();
  }
  loaded.render.width = width;
  loaded.render.height = height;
  return scene.primary_only ? primary_only(std::move(loaded)) : loaded;
}

renderer::Scene primary_only(renderer::Scene scene) {
  scene.lights.clear();
  for (renderer::Material &material : scene.materials) {
    material.type = renderer::MaterialType::diffuse;
  }
  for (renderer::Object &object : scene.objects) {
    object.real = true;
  }
  scene.render.max_bounces = 0;
  return scene;
}

} // namespace camhead::bench
