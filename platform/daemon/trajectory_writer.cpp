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
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw InputError("output.trajectory: cannot create '" + path + "': " + std::strerror(errno) +
                     " (check output.directory or $STATE_DIRECTORY)");
  const char header[] = "# mcslamd trajectory (TUM): t[s] tx ty tz qx qy qz qw, T_w_b\n";
  if (::write(fd_, header, sizeof(header) - 1) < 0) ++errors_;
}

bool TrajectoryWriter::append(const pose::PoseRecord& r) {
  if (fd_ < 0) return false;
  char line[256];
  const int n = formatTumLine(r, line);
  if (::write(fd_, line, static_cast<std::size_t>(n)) != n) {
    ++errors_;
    return false;
  }
  ++written_;
  return true;
}

bool TrajectoryWriter::sync() { return fd_ >= 0 && ::fsync(fd_) == 0; }

void TrajectoryWriter::close() {
  if (fd_ < 0) return;
  if (!sync()) ++errors_;
  ::close(fd_);
  fd_ = -1;
}

}  // namespace mcslam::platform
