#include "camhead/hal/discovery/devices.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <system_error>

#include <fcntl.h>
#include <linux/gpio.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include "camhead/hal/v4l2/device_file.h"
#include "camhead/hal/v4l2/pixel_formats.h"

namespace camhead::hal::discovery {
namespace {

namespace fs = std::filesystem;

// The first line of a sysfs attribute, empty where it cannot be read.
std::string attribute(const fs::path &file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  return line;
}

// Entries of `dir` whose names start with `prefix`, sorted as people count
// (video2 before video10).
std::vector<fs::path> entries(const fs::path &dir, const std::string &prefix) {
  std::vector<fs::path> found;
  std::error_code error;
  for (const fs::directory_entry &e : fs::directory_iterator(dir, error)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix, 0) == 0)
      found.push_back(e.path());
  }
  std::sort(found.begin(), found.end(), [](const fs::path &a, const fs::path &b) {
    const std::string x = a.filename().string(), y = b.filename().string();
    return x.size() != y.size() ? x.size() < y.size() : x < y;
  });
  return found;
}

// The udev links (by-id, by-path) under dev/v4l that point at `node`.
std::vector<std::string> links_to(const fs::path &dev, const fs::path &node) {
  std::vector<std::string> links;
  std::error_code error;
  for (const char *kind : {"by-id", "by-path"})
    for (const fs::directory_entry &e : fs::directory_iterator(dev / "v4l" / kind, error)) {
      const fs::path target = fs::weakly_canonical(e.path(), error);
      if (!error && target == fs::weakly_canonical(node, error))
        links.push_back(e.path().string());
    }
  std::sort(links.begin(), links.end());
  return links;
}

std::vector<std::string> formats_of(const v4l2::DeviceFile &file, std::uint32_t type) {
  std::vector<std::string> formats;
  for (std::uint32_t i = 0; i < 64; ++i) {
    v4l2_fmtdesc desc{};
    desc.index = i;
    desc.type = type;
    if (!file.ioctl(VIDIOC_ENUM_FMT, desc))
      break;
    formats.push_back(v4l2::fourcc_text(desc.pixelformat));
  }
  return formats;
}

} // namespace

std::vector<VideoNode> list_video_nodes(const fs::path &dev) {
  std::vector<VideoNode> nodes;
  for (const fs::path &path : entries(dev, "video")) {
    VideoNode node;
    node.path = path.string();
    node.links = links_to(dev, path);
    std::string error;
    const v4l2::DeviceFile file = v4l2::open_device(node.path, error);
    if (!file.is_open()) {
      node.problem = error;
      nodes.push_back(std::move(node));
      continue;
    }
    const std::optional<v4l2::DeviceInfo> info = v4l2::query_device(file, error);
    if (!info) {
      node.problem = error;
      nodes.push_back(std::move(node));
      continue;
    }
    node.driver = info->driver;
    node.card = info->card;
    node.capture = (info->caps & (V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_VIDEO_CAPTURE_MPLANE)) != 0;
    node.output = (info->caps & (V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_VIDEO_OUTPUT_MPLANE)) != 0;
    node.formats =
        formats_of(file, node.capture ? V4L2_BUF_TYPE_VIDEO_CAPTURE : V4L2_BUF_TYPE_VIDEO_OUTPUT);
    nodes.push_back(std::move(node));
  }
  return nodes;
}

std::vector<DisplayCard> list_display_cards(const fs::path &sysfs) {
  std::vector<DisplayCard> cards;
  const fs::path drm = sysfs / "class" / "drm";
  for (const fs::path &path : entries(drm, "card")) {
    const std::string name = path.filename().string();
    if (name.find('-') != std::string::npos)
      continue; // a connector (card0-HDMI-A-1), listed under its card
    DisplayCard card;
    card.card = name;
    std::error_code error;
    card.driver = fs::read_symlink(path / "device" / "driver", error).filename().string();
    for (const fs::path &connector : entries(drm, name + "-"))
      card.connectors.push_back(
          {connector.filename().string().substr(name.size() + 1), attribute(connector / "status")});
    cards.push_back(std::move(card));
  }
  return cards;
}

std::vector<GpioChip> list_gpio_chips(const fs::path &dev) {
  std::vector<GpioChip> chips;
  for (const fs::path &path : entries(dev, "gpiochip")) {
    GpioChip chip;
    chip.name = path.filename().string();
    // GPIO_GET_CHIPINFO_IOCTL, the uapi call libgpiod makes: no library.
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd >= 0) {
      gpiochip_info info{};
      if (::ioctl(fd, GPIO_GET_CHIPINFO_IOCTL, &info) == 0) {
        chip.label = std::string(info.label, strnlen(info.label, sizeof info.label));
        chip.lines = info.lines;
      }
      ::close(fd);
    }
    chips.push_back(std::move(chip));
  }
  return chips;
}

std::vector<UsbDevice> list_usb_devices(unsigned vendor_id, unsigned product_id,
                                        const fs::path &sysfs) {
  std::vector<UsbDevice> found;
  for (const fs::path &path : entries(sysfs / "bus" / "usb" / "devices", "")) {
    const std::string vid = attribute(path / "idVendor");
    const std::string pid = attribute(path / "idProduct");
    if (vid.empty() || pid.empty())
      continue;
    try {
      if (std::stoul(vid, nullptr, 16) != vendor_id || std::stoul(pid, nullptr, 16) != product_id)
        continue;
    } catch (const std::exception &) {
      continue; // not hexadecimal: not a device directory
    }
    found.push_back({path.filename().string(), vendor_id, product_id, attribute(path / "serial"),
                     attribute(path / "product")});
  }
  return found;
}

} // namespace camhead::hal::discovery
