// Reading a whole input file: what comes back, and the bound that keeps a
// path such as /dev/zero from becoming an endless allocation.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "camhead/base/input_file.h"

#include <gtest/gtest.h>

namespace camhead::base {
namespace {

class InputFile : public ::testing::Test {
protected:
  void SetUp() override { std::filesystem::create_directories(dir_); }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  const std::filesystem::path dir_ =
      std::filesystem::temp_directory_path() / ("camhead_input_" + std::to_string(::getpid()));
};

TEST_F(InputFile, ReadsTheWholeFileUpToItsBound) {
  const std::filesystem::path file = dir_ / "a.bin";
  std::string bytes("\0\r\n\xff", 4);
  bytes.append(200000, 'x');
  std::ofstream(file, std::ios::binary) << bytes;
  std::string error;
  EXPECT_EQ(read_input_file(file, bytes.size(), error), bytes);
  std::vector<unsigned char> into(10, 7); // replaced, not appended to
  ASSERT_TRUE(read_input_file(file, bytes.size(), into, error));
  EXPECT_EQ(std::string(into.begin(), into.end()), bytes);
  EXPECT_FALSE(read_input_file(file, bytes.size() - 1, error));
  EXPECT_EQ(error, "is larger than 195 KiB");
}

TEST_F(InputFile, EndlessDevicesStopAtTheBound) {
  std::string error;
  EXPECT_FALSE(read_input_file("/dev/zero", std::size_t(1) << 20, error));
  EXPECT_EQ(error, "is larger than 1 MiB");
  std::vector<unsigned char> bytes;
  EXPECT_FALSE(read_input_file("/dev/urandom", std::size_t(1) << 20, bytes, error));
  EXPECT_EQ(error, "is larger than 1 MiB");
  EXPECT_LE(bytes.size(), std::size_t(1) << 20);
}

TEST_F(InputFile, FoldersAndMissingFilesAreNamed) {
  std::string error;
  EXPECT_FALSE(read_input_file(dir_, 1024, error));
  EXPECT_EQ(error, "is a folder, not a file");
  EXPECT_FALSE(read_input_file(dir_ / "none", 1024, error));
  EXPECT_EQ(error, "cannot be opened: No such file or directory");
}

} // namespace
} // namespace camhead::base
