#include "mcslam/core/synced_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace mcslam {

namespace {

bool fail(std::string* error, const std::string& what, const std::string& path) {
  if (error) *error = what + " '" + path + "': " + std::strerror(errno);
  return false;
}

bool writeAll(int fd, std::string_view bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = ENOSPC;
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace

bool writeFileSynced(const std::string& path, std::string_view bytes, std::string* error) {
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return fail(error, "cannot create", tmp);
  const char* failed_step = nullptr;
  if (!writeAll(fd, bytes)) {
    failed_step = "cannot write";
  } else if (::fsync(fd) != 0) {
    failed_step = "cannot fsync";
  }
  if (failed_step) {
    fail(error, failed_step, tmp);
    ::close(fd);
    ::unlink(tmp.c_str());
    return false;
  }
  ::close(fd);
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    fail(error, "cannot rename to", path);
    ::unlink(tmp.c_str());
    return false;
  }
  // The rename itself is durable only once the folder is synced.
  const std::string parent = std::filesystem::path(path).parent_path().string();
  const std::string dir = parent.empty() ? std::string(1, '.') : parent;
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0) return fail(error, "cannot open folder", dir);
  const bool synced = ::fsync(dfd) == 0;
  ::close(dfd);
  return synced || fail(error, "cannot fsync folder", dir);
}

}  // namespace mcslam
