// camhead devices' discovery on a sysfs and /dev laid out by the test: DRM
// cards with their connectors, USB devices by id, V4L2 nodes that are not
// character devices (reported with the reason, not skipped), GPIO chips.
#include <filesystem>
#include <fstream>
#include <string>

#include "camhead/hal/discovery/devices.h"

#include <gtest/gtest.h>

namespace camhead::hal::discovery {
namespace {

namespace fs = std::filesystem;

class Discovery : public ::testing::Test {
protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("camhead_discovery_" +
             std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  void file(const fs::path &path, const std::string &text) const {
    fs::create_directories((root_ / path).parent_path());
    std::ofstream(root_ / path) << text << "\n";
  }

  fs::path root_;
};

TEST_F(Discovery, DisplayCardsWithTheirConnectorsAndDriver) {
  file("sys/devices/pci0000:00/0000:00:02.0/drm/card0/dev", "226:0");
  fs::create_directories(root_ / "sys/bus/pci/drivers/bochs-drm");
  fs::create_directories(root_ / "sys/class/drm");
  fs::create_directories(root_ / "sys/devices/pci0000:00/0000:00:02.0/drm/card0/device");
  fs::create_directory_symlink(root_ / "sys/bus/pci/drivers/bochs-drm",
                               root_ /
                                   "sys/devices/pci0000:00/0000:00:02.0/drm/card0/device/driver");
  fs::create_directory_symlink(root_ / "sys/devices/pci0000:00/0000:00:02.0/drm/card0",
                               root_ / "sys/class/drm/card0");
  file("sys/class/drm/card0-Virtual-1/status", "connected");
  file("sys/class/drm/card0-HDMI-A-1/status", "disconnected");
  file("sys/class/drm/renderD128/dev", "226:128");
  const std::vector<DisplayCard> cards = list_display_cards(root_ / "sys");
  ASSERT_EQ(cards.size(), 1u);
  EXPECT_EQ(cards[0].card, "card0");
  EXPECT_EQ(cards[0].driver, "bochs-drm");
  ASSERT_EQ(cards[0].connectors.size(), 2u);
  EXPECT_EQ(cards[0].connectors[0].name, "HDMI-A-1");
  EXPECT_EQ(cards[0].connectors[0].status, "disconnected");
  EXPECT_EQ(cards[0].connectors[1].name, "Virtual-1");
  EXPECT_EQ(cards[0].connectors[1].status, "connected");
}

TEST_F(Discovery, UsbDevicesByVendorAndProduct) {
  file("sys/bus/usb/devices/1-1/idVendor", "1209");
  file("sys/bus/usb/devices/1-1/idProduct", "0001");
  file("sys/bus/usb/devices/1-1/serial", "0042");
  file("sys/bus/usb/devices/1-1/product", "camhead lens board");
  file("sys/bus/usb/devices/1-2/idVendor", "046d");
  file("sys/bus/usb/devices/1-2/idProduct", "0825");
  file("sys/bus/usb/devices/1-1:1.0/bInterfaceClass", "ff"); // an interface, no ids
  const std::vector<UsbDevice> found = list_usb_devices(0x1209, 0x0001, root_ / "sys");
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].sysfs_name, "1-1");
  EXPECT_EQ(found[0].serial, "0042");
  EXPECT_EQ(found[0].product, "camhead lens board");
  EXPECT_TRUE(list_usb_devices(0x1209, 0x0002, root_ / "sys").empty());
}

TEST_F(Discovery, VideoNodesThatCannotBeAskedSayWhy) {
  file("dev/video10", "not a device");
  file("dev/video2", "not a device");
  file("dev/vhost-net", "");
  const std::vector<VideoNode> nodes = list_video_nodes(root_ / "dev");
  ASSERT_EQ(nodes.size(), 2u);
  EXPECT_EQ(fs::path(nodes[0].path).filename(), "video2") << "counted, not sorted as text";
  EXPECT_EQ(fs::path(nodes[1].path).filename(), "video10");
  for (const VideoNode &n : nodes) {
    EXPECT_FALSE(n.problem.empty());
    EXPECT_NE(n.problem.find("is not a device node"), std::string::npos) << n.problem;
    EXPECT_FALSE(n.capture || n.output);
  }
}

TEST_F(Discovery, NothingThereIsAnEmptyList) {
  EXPECT_TRUE(list_video_nodes(root_ / "dev").empty());
  EXPECT_TRUE(list_display_cards(root_ / "sys").empty());
  EXPECT_TRUE(list_gpio_chips(root_ / "dev").empty());
  EXPECT_TRUE(list_usb_devices(0x1209, 0x0001, root_ / "sys").empty());
}

} // namespace
} // namespace camhead::hal::discovery
