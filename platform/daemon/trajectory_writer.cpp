#include "daemon/trajectory_writer.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>

#include "mcslam/core/error.hpp"

namespace mcslam::platform {

int formatTumLine(const pose::PoseRecord& r, char* out) {
  char* p = out;
  char* const end = out + 256;
  // Seconds with exactly nine decimals, from integers: exact to the nanosecond.
  int64_t t = r.capture_time_ns;
  if (t < 0) {
    *p++ = '-';
    t = -t;
  }
  p = std::to_chars(p, end, t / 1000000000).ptr;
  *p++ = '.';
  char frac[16];
  std::snprintf(frac, sizeof(frac), "%09lld", static_cast<long long>(t % 1000000000));
  std::memcpy(p, frac, 9);
  p += 9;
  const double values[7] = {r.position[0],    r.position[1],    r.position[2],   r.orientation[0],
                            r.orientation[1], r.orientation[2], r.orientation[3]};
  for (double v : values) {
    *p++ = ' ';
    p = std::to_chars(p, end, v).ptr;  // shortest form that reads back to the same double
  }
  *p++ = '\n';
  return static_cast<int>(p - out);
}

TrajectoryWriter::TrajectoryWriter(const std::string& path) : path_(path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && st.st_size > 0) ::rename(path.c_str(), (path + ".previous").c_str());
  if (!openFile(O_TRUNC) && fd_ < 0)
    throw InputError("output.trajectory: cannot create '" + path + "': " + std::strerror(errno) +
                     " (check output.directory or $STATE_DIRECTORY)");
}

bool TrajectoryWriter::openFile(int flags) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC | flags, 0644);
  if (fd_ < 0) return false;
  whole_lines_size_ = 0;
  const char header[] = "# mcslamd trajectory (TUM): t[s] tx ty tz qx qy qz qw, T_w_b\n";
  const int n = static_cast<int>(sizeof(header) - 1);
  if (writeAll(header, n)) {
    whole_lines_size_ = n;
    return true;
  }
  fail(errno);
  return false;
}

bool TrajectoryWriter::writeAll(const char* bytes, int n) {
  // A short write is followed by another for the rest, which either completes the line or says why it cannot.
  int done = 0;
  while (done < n) {
    const ssize_t w = ::write(fd_, bytes + done, static_cast<std::size_t>(n - done));
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      if (w == 0) errno = EIO;
      return false;
    }
    done += static_cast<int>(w);
  }
  return true;
}

void TrajectoryWriter::fail(int err) {
  last_errno_.store(err ? err : EIO, std::memory_order_relaxed);
  errors_.fetch_add(1, std::memory_order_relaxed);
  if (fd_ >= 0) (void)::ftruncate(fd_, whole_lines_size_);  // no torn line (fails harmlessly on a device)
}

bool TrajectoryWriter::ensureFileExists() {
  struct stat st {};
  if (fd_ >= 0 && ::fstat(fd_, &st) == 0 && st.st_nlink > 0) return true;
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (!openFile(0)) {
    if (fd_ < 0) last_errno_.store(errno, std::memory_order_relaxed);
    return false;
  }
  reopened_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

bool TrajectoryWriter::append(const pose::PoseRecord& r) {
  if (!ensureFileExists()) {
    errors_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  char line[256];
  const int n = formatTumLine(r, line);
  if (!writeAll(line, n)) {
    fail(errno);
    return false;
  }
  whole_lines_size_ += n;
  written_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

bool TrajectoryWriter::sync() { return fd_ >= 0 && ::fsync(fd_) == 0; }

void TrajectoryWriter::close() {
  if (fd_ < 0) return;
  if (!sync()) fail(errno);
  ::close(fd_);
  fd_ = -1;
}

}  // namespace mcslam::platform
