// camhead devices: what this machine offers a rig (cameras, outputs, lens
// encoders, Vulkan devices), each with what to write in a board file or on
// the command line to use it.
#include <cstdio>
#include <exception>
#include <string>

#include "camhead/hal/camera/libcamera/libcamera_camera.h"
#include "camhead/hal/discovery/devices.h"
#include "camhead/hal/lens/usb/usb_lens_protocol.h"
#include "camhead/renderer/gpu_tracer.h"
#include "cli/commands.h"
#include "tracking/marker_tracker.h"
#include "web/web_server.h"

namespace camhead::cli {
namespace {

namespace discovery = hal::discovery;

int exit_status = 0;

std::string joined(const std::vector<std::string> &items) {
  std::string text;
  for (const std::string &item : items)
    text += (text.empty() ? "" : " ") + item;
  return text;
}

void list_video(const std::vector<discovery::VideoNode> &nodes) {
  std::printf("Cameras (board \"camera\": {\"type\": \"v4l2\", \"device\": ...}):\n");
  int cameras = 0;
  for (const discovery::VideoNode &n : nodes) {
    if (!n.problem.empty()) {
      std::printf("  %s: %s\n", n.path.c_str(), n.problem.c_str());
      continue;
    }
    if (!n.capture)
      continue;
    ++cameras;
    // A by-id name survives replugging into another port; prefer it.
    const std::string name = n.links.empty() ? n.path : n.links.front();
    std::printf("  %s  (%s, %s: %s)  formats %s\n", name.c_str(), n.path.c_str(), n.driver.c_str(),
                n.card.c_str(), joined(n.formats).c_str());
  }
  try {
    for (const std::string &camera : hal::camera::list_libcamera_cameras()) {
      ++cameras;
      std::printf("  libcamera %s  (board \"camera\": {\"type\": \"libcamera\", \"camera_id\": "
                  "...})\n",
                  camera.c_str());
    }
  } catch (const std::exception &e) {
    std::printf("  libcamera cameras not listed: %s\n", e.what());
  }
  if (cameras == 0)
    std::printf("  none found (the simulated camera is always there: --board sim)\n");
  std::printf("Webcam outputs (camhead run --output v4l2:DEVICE):\n");
  int outputs = 0;
  for (const discovery::VideoNode &n : nodes)
    if (n.problem.empty() && n.output) {
      ++outputs;
      std::printf("  v4l2:%s  (%s: %s)\n", n.path.c_str(), n.driver.c_str(), n.card.c_str());
    }
  if (outputs == 0)
    std::printf(
        "  none found (modprobe v4l2loopback video_nr=10 exclusive_caps=1 "
        "card_label=camhead;\n        systemd/camhead-v4l2loopback.conf is the options file)\n");
}

void list_displays(const std::vector<discovery::DisplayCard> &cards) {
  std::printf("Displays (camhead run --output drm:CARD[:CONNECTOR]):\n");
  if (cards.empty())
    std::printf("  none found\n");
  for (const discovery::DisplayCard &card : cards)
    for (const discovery::DisplayConnector &c : card.connectors)
      std::printf("  drm:%s:%s  (%s, %s)\n", card.card.c_str(), c.name.c_str(), card.driver.c_str(),
                  c.status.c_str());
}

void list_lens_encoders() {
  std::printf("Lens encoders (board \"lens\": \"sources\"):\n");
  const auto boards =
      discovery::list_usb_devices(hal::lens::kUsbLensVendorId, hal::lens::kUsbLensProductId);
  for (const discovery::UsbDevice &b : boards)
    std::printf("  {\"type\": \"usb\", \"vendor_id\": \"%04x\", \"product_id\": \"%04x\", "
                "\"serial\": \"%s\"}  (USB %s, %s)\n",
                b.vendor_id, b.product_id, b.serial.c_str(), b.sysfs_name.c_str(),
                b.product.c_str());
  const auto chips = discovery::list_gpio_chips();
  for (const discovery::GpioChip &c : chips)
    std::printf("  {\"type\": \"gpio\", \"chip\": \"%s\", ...}  (%s, %u lines)\n",
                c.label.empty() ? c.name.c_str() : c.label.c_str(), c.name.c_str(), c.lines);
  if (boards.empty() && chips.empty())
    std::printf("  no USB lens board and no GPIO chip found; FreeD and OpenTrackIO sources "
                "listen on UDP and need no device\n");
}

void list_pose_sources() {
  std::printf("Camera pose (board \"pose\"):\n"
              "  {\"type\": \"static\", \"position\": ..., \"look_at\": ...}\n"
              "  {\"type\": \"freed\" or \"opentrackio\"}  a tracker's, in the datagrams of "
              "a lens source of that type\n");
  const std::string problem = pipeline::marker_module_problem();
  if (problem.empty())
    std::printf("  {\"type\": \"marker\", \"board\": \"MARKERS.json\"}  found in the "
                "frames (%s loads)\n",
                pipeline::marker_module_name());
  else
    std::printf("  marker: not here: %s\n", problem.c_str());
}

void list_operator_page() {
  const std::string problem = pipeline::web::web_module_problem();
  if (problem.empty())
    std::printf("Operator page (camhead run --http ADDR:PORT, board \"http\"): can be served "
                "(%s loads)\n",
                pipeline::web::web_module_name());
  else
    std::printf("Operator page: not here: %s\n", problem.c_str());
}

int list_vulkan() {
  try {
    const auto devices = renderer::list_gpu_devices();
    if (devices.empty()) {
      std::printf("Vulkan devices: none (install mesa-vulkan-drivers for lavapipe).\n");
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

int list_devices() {
  list_video(discovery::list_video_nodes());
  list_displays(discovery::list_display_cards());
  list_lens_encoders();
  list_pose_sources();
  list_operator_page();
  return list_vulkan();
}

} // namespace

int exit_code() {
  return exit_status;
}
void set_exit_code(int code) {
  exit_status = code;
}

void add_devices_command(CLI::App &app) {
  CLI::App *cmd = app.add_subcommand(
      "devices", "List the cameras, webcam and display outputs, lens encoders, camera pose\n"
                 "sources and Vulkan devices this machine has, with the board field or\n"
                 "option that uses each");
  cmd->callback([] { set_exit_code(list_devices()); });
}

} // namespace camhead::cli
