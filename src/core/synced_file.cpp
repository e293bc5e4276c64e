#include "mcslam/core/synced_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
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

// A path that names a device, a pipe or a socket (/dev/stdout, a FIFO a consumer reads) is written to as it is: a
// rename would replace the node with a regular file, and such a target has no previous content to keep.
bool isSpecialFile(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode);
}

bool writeSpecialFile(const std::string& path, std::string_view bytes, std::string* error) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) return fail(error, "cannot open", path);
  const bool written = writeAll(fd, bytes);
  if (!written) fail(error, "cannot write", path);
  ::close(fd);
  return written;
}

}  // namespace

SyncedFileTarget::SyncedFileTarget(const std::string& file) : path(file), tmp(file + ".tmp") {
  const std::string parent = std::filesystem::path(file).parent_path().string();
  folder = parent.empty() ? std::string(1, '.') : parent;
}

bool writeFileSynced(const std::string& path, std::string_view bytes, std::string* error) {
  return writeFileSynced(SyncedFileTarget(path), bytes, error);
}

bool writeFileSynced(const SyncedFileTarget& target, std::string_view bytes, std::string* error) {
  if (isSpecialFile(target.path)) return writeSpecialFile(target.path, bytes, error);
  const int fd = ::open(target.tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return fail(error, "cannot create", target.tmp);
  const char* failed_step = nullptr;
  if (!writeAll(fd, bytes)) {
    failed_step = "cannot write";
  } else if (::fsync(fd) != 0) {
    failed_step = "cannot fsync";
  }
  if (failed_step) {
    fail(error, failed_step, target.tmp);
    ::close(fd);
    ::unlink(target.tmp.c_str());
    return false;
  }
  ::close(fd);
  if (::rename(target.tmp.c_str(), target.path.c_str()) != 0) {
    fail(error, "cannot rename to", target.path);
    ::unlink(target.tmp.c_str());
    return false;
  }
  // The rename itself is durable only once the folder is synced.
  const int dfd = ::open(target.folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0) return fail(error, "cannot open folder", target.folder);
  const bool synced = ::fsync(dfd) == 0;
  ::close(dfd);
  return synced || fail(error, "cannot fsync folder", target.folder);
}

}  // namespace mcslam
