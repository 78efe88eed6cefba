// What open_drm_sink says when it cannot open: the card (and where it got
// that far, the connector) is named with the reason, before any device is
// touched for what the options alone show to be wrong.
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <unistd.h>

#include "camhead/hal/output/drm/drm_sink.h"

#include <gtest/gtest.h>

namespace camhead::hal::output {
namespace {

std::string open_error(const DrmSinkOptions &options) {
  try {
    (void)open_drm_sink(options);
  } catch (const DrmSinkError &e) {
    return e.what();
  }
  ADD_FAILURE() << "no error thrown";
  return {};
}

DrmSinkOptions options(std::string card) {
  DrmSinkOptions o;
  o.card = std::move(card);
  o.width = 640;
  o.height = 480;
  return o;
}

TEST(DrmSinkOpen, MissingCardIsNamed) {
  const std::string error = open_error(options("/nonexistent/dri/card7"));
  EXPECT_EQ(error.rfind("/nonexistent/dri/card7: cannot open: No such file or directory", 0), 0u)
      << error;
}

TEST(DrmSinkOpen, UnknownDriverListsTheCards) {
  const std::string error = open_error(options("no-such-drm-driver"));
  EXPECT_NE(error.find("no card with driver 'no-such-drm-driver'"), std::string::npos) << error;
  EXPECT_NE(error.find("/dev/dri"), std::string::npos) << error;
}

TEST(DrmSinkOpen, RegularFileIsRefused) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("camhead_drm_" + std::to_string(::getpid()));
  std::ofstream(file) << "not a card";
  const std::string error = open_error(options(file.string()));
  std::filesystem::remove(file);
  EXPECT_NE(error.find("not a device node"), std::string::npos) << error;
}

TEST(DrmSinkOpen, OptionsCheckedBeforeTheDevice) {
  DrmSinkOptions bad_mode = options("/nonexistent/card0");
  bad_mode.mode = "1920x1080@fast";
  std::string error = open_error(bad_mode);
  EXPECT_NE(error.find("/nonexistent/card0: mode '1920x1080@fast'"), std::string::npos) << error;

  DrmSinkOptions empty_frame = options("/nonexistent/card0");
  empty_frame.width = 0;
  error = open_error(empty_frame);
  EXPECT_NE(error.find("/nonexistent/card0: frame:"), std::string::npos) << error;

  EXPECT_NE(open_error(options("")).find("no card named"), std::string::npos);
}

} // namespace
} // namespace camhead::hal::output
