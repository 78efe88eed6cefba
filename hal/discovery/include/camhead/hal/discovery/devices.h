// What devices this machine has for a rig, for `camhead devices`: cameras and
// loopback webcams (V4L2 nodes), displays (DRM cards and their connectors),
// GPIO chips and camhead USB lens boards. Found through sysfs and, for V4L2,
// VIDIOC_QUERYCAP; nothing is opened for streaming and nothing is changed.
//
// `sysfs` and `dev` name the roots ("/sys", "/dev") so that tests can lay out
// a tree of their own.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace camhead::hal::discovery {

struct VideoNode {
  std::string path;                 // /dev/videoN
  std::vector<std::string> links;   // /dev/v4l/by-id/... and by-path names for it
  std::string driver, card;         // from QUERYCAP; empty with `problem` set
  bool capture = false;             // a camera
  bool output = false;              // a loopback webcam (or another output node)
  std::vector<std::string> formats; // "YUYV", "MJPG", ... (capture or output)
  std::string problem;              // why it could not be asked (permission, busy)
};

struct DisplayConnector {
  std::string name;   // "HDMI-A-1", "Virtual-1"
  std::string status; // "connected", "disconnected", "unknown"
};
struct DisplayCard {
  std::string card;   // "card0"
  std::string driver; // "bochs-drm", "vc4", ...
  std::vector<DisplayConnector> connectors;
};

struct GpioChip {
  std::string name;  // "gpiochip0"
  std::string label; // "pinctrl-bcm2711", "gpio-sim.0-node0"; empty if it could not be asked
  unsigned lines = 0;
};

struct UsbDevice {
  std::string sysfs_name; // "1-1.3"
  unsigned vendor_id = 0, product_id = 0;
  std::string serial, product;
};

[[nodiscard]] std::vector<VideoNode> list_video_nodes(const std::filesystem::path &dev = "/dev");
[[nodiscard]] std::vector<DisplayCard>
list_display_cards(const std::filesystem::path &sysfs = "/sys");
[[nodiscard]] std::vector<GpioChip> list_gpio_chips(const std::filesystem::path &dev = "/dev");
// USB devices with this vendor and product id (the camhead lens board's).
[[nodiscard]] std::vector<UsbDevice> list_usb_devices(unsigned vendor_id, unsigned product_id,
                                                      const std::filesystem::path &sysfs = "/sys");

} // namespace camhead::hal::discovery
