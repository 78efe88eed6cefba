// camhead devices: what this machine offers the renderer.
#include <cstdio>
#include <exception>

#include "camhead/renderer/gpu_tracer.h"
#include "commands.h"

namespace camhead::cli {
namespace {

int exit_status = 0;

int list_devices() {
  try {
    const auto devices = renderer::list_gpu_devices();
    if (devices.empty()) {
      std::printf("No Vulkan device found (install mesa-vulkan-drivers for lavapipe).\n");
      return 1;
    }
    std::printf("Vulkan devices (camhead render --device INDEX|NAME):\n");
    std::fputs(renderer::format_gpu_devices(devices).c_str(), stdout);
    return 0;
  } catch (const std::exception &e) {
    std::fprintf(stderr, "Vulkan error: %s\n", e.what());
    return 3;
  }
}

} // namespace

int exit_code() {
  return exit_status;
}
void set_exit_code(int code) {
  exit_status = code;
}

void add_devices_command(CLI::App &app) {
  CLI::App *cmd = app.add_subcommand("devices", "List the Vulkan devices the renderer can use");
  cmd->callback([] { set_exit_code(list_devices()); });
}

} // namespace camhead::cli
