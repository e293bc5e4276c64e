#include "daemon/synced_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace mcslam::platform {

namespace {
bool fail(std::string* error, const std::string& what, const std::string& path) {
  if (error) *error = what + " '" + path + "': " + std::strerror(errno);
  return false;
}
}  // namespace

bool writeFileSynced(const std::string& path, const std::string& text, std::string* error) {
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return fail(error, "cannot create", tmp);
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      fail(error, "cannot write", tmp);
      ::close(fd);
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    fail(error, "cannot fsync", tmp);
    ::close(fd);
    return false;
  }
  ::close(fd);
  if (::rename(tmp.c_str(), path.c_str()) != 0) return fail(error, "cannot rename to", path);
  // The rename itself is durable only once the folder is synced.
  const std::string parent = std::filesystem::path(path).parent_path().string();
  const std::string dir = parent.empty() ? std::string(1, '.') : parent;
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0) return fail(error, "cannot open folder", dir);
  const bool synced = ::fsync(dfd) == 0;
  ::close(dfd);
  return synced || fail(error, "cannot fsync folder", dir);
}

}  // namespace mcslam::platform
