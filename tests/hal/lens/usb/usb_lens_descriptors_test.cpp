// The FunctionFS blobs the VM gadget writes to ep0, checked field by field
// against the kernel's own structs and constants in <linux/usb/functionfs.h>
// and <linux/usb/ch9.h>: a wrong blob makes the gadget's first write fail
// with EINVAL inside the VM, far from any useful message, so it is caught
// here instead.
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <endian.h>
#include <linux/usb/ch9.h>
#include <linux/usb/functionfs.h>

#include "camhead/hal/lens/usb/usb_lens_descriptors.h"
#include "camhead/hal/lens/usb/usb_lens_protocol.h"

#include <gtest/gtest.h>

namespace camhead::hal::lens {
namespace {

template <typename T> T read_at(const std::vector<std::uint8_t> &blob, std::size_t at) {
  T value{};
  EXPECT_LE(at + sizeof(T), blob.size());
  if (at + sizeof(T) <= blob.size()) {
    std::memcpy(&value, blob.data() + at, sizeof(T));
  }
  return value;
}

// One speed's interface + endpoint descriptors, as the kernel reads them.
void expect_speed(const std::vector<std::uint8_t> &blob, std::size_t at, std::uint8_t interval) {
  const auto intf = read_at<usb_interface_descriptor>(blob, at);
  EXPECT_EQ(intf.bLength, USB_DT_INTERFACE_SIZE);
  EXPECT_EQ(intf.bDescriptorType, USB_DT_INTERFACE);
  EXPECT_EQ(intf.bInterfaceNumber, 0);
  EXPECT_EQ(intf.bAlternateSetting, 0);
  EXPECT_EQ(intf.bNumEndpoints, 1);
  EXPECT_EQ(intf.bInterfaceClass, USB_CLASS_VENDOR_SPEC);
  EXPECT_EQ(intf.bInterfaceSubClass, kUsbLensInterfaceSubClass);
  EXPECT_EQ(intf.bInterfaceProtocol, kUsbLensInterfaceProtocol);
  EXPECT_EQ(intf.iInterface, 1); // the first (only) string of the strings blob

  const auto ep = read_at<usb_endpoint_descriptor_no_audio>(blob, at + USB_DT_INTERFACE_SIZE);
  EXPECT_EQ(ep.bLength, USB_DT_ENDPOINT_SIZE);
  EXPECT_EQ(ep.bDescriptorType, USB_DT_ENDPOINT);
  EXPECT_EQ(ep.bEndpointAddress, USB_DIR_IN | 1);
  EXPECT_EQ(ep.bmAttributes, USB_ENDPOINT_XFER_INT);
  EXPECT_EQ(le16toh(ep.wMaxPacketSize), 64);
  EXPECT_EQ(ep.bInterval, interval);
}

TEST(UsbLensDescriptors, KernelStructSizesMatchTheBytesWeWrite) {
  static_assert(sizeof(usb_interface_descriptor) == kUsbInterfaceDescriptorSize);
  static_assert(sizeof(usb_endpoint_descriptor_no_audio) == kUsbEndpointDescriptorSize);
  EXPECT_EQ(usb_lens_interface_descriptors(UsbSpeed::full).size(),
            USB_DT_INTERFACE_SIZE + USB_DT_ENDPOINT_SIZE);
}

TEST(UsbLensDescriptors, FunctionFsDescriptorsBlobIsV2WithFullAndHighSpeed) {
  const std::vector<std::uint8_t> blob = functionfs_descriptors();
  const auto head = read_at<usb_functionfs_descs_head_v2>(blob, 0);
  EXPECT_EQ(le32toh(head.magic), FUNCTIONFS_DESCRIPTORS_MAGIC_V2);
  EXPECT_EQ(le32toh(head.length), blob.size());
  EXPECT_EQ(le32toh(head.flags), FUNCTIONFS_HAS_FS_DESC | FUNCTIONFS_HAS_HS_DESC);

  // The v2 header is followed by one count per flag, in flag order.
  std::size_t at = sizeof head;
  const std::uint32_t fs_count = le32toh(read_at<std::uint32_t>(blob, at));
  const std::uint32_t hs_count = le32toh(read_at<std::uint32_t>(blob, at + 4));
  at += 8;
  EXPECT_EQ(fs_count, 2u);
  EXPECT_EQ(hs_count, 2u);

  // Walk the descriptors by bLength, as the kernel's ffs_do_descs does: the
  // counts must account for every byte.
  std::size_t walked = at, descriptors = 0;
  while (walked < blob.size()) {
    ASSERT_GE(blob[walked], 2u);
    walked += blob[walked];
    ++descriptors;
  }
  EXPECT_EQ(walked, blob.size());
  EXPECT_EQ(descriptors, fs_count + hs_count);

  expect_speed(blob, at, 1);                                                // 1 ms frames
  expect_speed(blob, at + USB_DT_INTERFACE_SIZE + USB_DT_ENDPOINT_SIZE, 4); // 8 microframes
}

TEST(UsbLensDescriptors, FunctionFsStringsBlobHasTheInterfaceName) {
  const std::vector<std::uint8_t> blob = functionfs_strings();
  const auto head = read_at<usb_functionfs_strings_head>(blob, 0);
  EXPECT_EQ(le32toh(head.magic), FUNCTIONFS_STRINGS_MAGIC);
  EXPECT_EQ(le32toh(head.length), blob.size());
  EXPECT_EQ(le32toh(head.str_count), 1u);
  EXPECT_EQ(le32toh(head.lang_count), 1u);
  std::size_t at = sizeof head;
  EXPECT_EQ(le16toh(read_at<std::uint16_t>(blob, at)), 0x0409);
  at += 2;
  const std::string name(kUsbLensInterfaceName);
  ASSERT_EQ(blob.size(), at + name.size() + 1);
  EXPECT_EQ(std::string(blob.begin() + static_cast<std::ptrdiff_t>(at), blob.end() - 1), name);
  EXPECT_EQ(blob.back(), 0);
}

} // namespace
} // namespace camhead::hal::lens
