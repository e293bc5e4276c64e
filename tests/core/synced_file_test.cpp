// writeFileSynced: a regular file is replaced whole or not at all; a pipe or device path is written to, not replaced.
#include "mcslam/core/synced_file.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "test_support.hpp"

using namespace mcslam;

namespace {

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST(SyncedFile, ReplacesTheFileWholeAndLeavesNoTemporary) {
  test::TempDir dir("synced_file");
  const std::string path = dir.file("out.csv");
  std::string error;
  ASSERT_TRUE(writeFileSynced(path, "first\n", &error)) << error;
  ASSERT_TRUE(writeFileSynced(path, "second, longer\n", &error)) << error;
  EXPECT_EQ(readAll(path), "second, longer\n");
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
}

TEST(SyncedFile, AFolderThatIsNotThereIsNamedInTheError) {
  test::TempDir dir("synced_file");
  const std::string path = dir.file("missing/out.csv");
  std::string error;
  EXPECT_FALSE(writeFileSynced(path, "bytes", &error));
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_FALSE(std::filesystem::exists(path));
}

// Writing "to" a FIFO (or /dev/stdout) means into it: the reader gets the bytes and the FIFO stays a FIFO. A rename
// over it would have replaced it with a regular file (as root, /dev/full or /dev/null too).
TEST(SyncedFile, APipeIsWrittenIntoAndNotReplaced) {
  test::TempDir dir("synced_file");
  const std::string path = dir.file("pipe");
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  // The reading end, open before the write (without blocking): the bytes wait in the pipe's buffer.
  const int reader = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  ASSERT_GE(reader, 0);
  std::string error;
  EXPECT_TRUE(writeFileSynced(path, "frame,t\n0,1.0\n", &error)) << error;
  char buffer[64];
  const ssize_t n = ::read(reader, buffer, sizeof(buffer));
  ::close(reader);
  EXPECT_EQ(std::string(buffer, static_cast<std::size_t>(std::max<ssize_t>(n, 0))), "frame,t\n0,1.0\n");
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
}
