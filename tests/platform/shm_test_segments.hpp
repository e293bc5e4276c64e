#pragma once
// Shared-memory segments made by hand for the tests of the pose segment's reader, writer and echo tool: a
// header saying what the test needs (a writer pid that is alive or dead, a `published` no slot backs); and the
// records those tests publish.
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <string>

#include "mcslam/pose_shm.hpp"
#include "shm/pose_shm_writer.hpp"

namespace mcslam::test {

inline std::string uniqueShmName(const char* tag) {
  return std::string("/mcslam-test-") + tag + "-" + std::to_string(::getpid());
}

// Every field derived from the sequence, so a mix of two records is detectable.
inline pose::PoseRecord recordFor(uint64_t seq) {
  pose::PoseRecord r;
  r.sequence = seq;
  r.frame_sequence = seq * 3;
  r.capture_time_ns = static_cast<int64_t>(seq) * 50000000;
  r.publish_time_ns = static_cast<int64_t>(seq) * 7;
  for (int i = 0; i < 3; ++i) r.position[i] = static_cast<double>(seq) + i * 0.25;
  const double a = static_cast<double>(seq % 1000) * 1e-3;
  r.orientation[0] = std::sin(a);
  r.orientation[1] = 0;
  r.orientation[2] = 0;
  r.orientation[3] = std::cos(a);
  r.tracking = static_cast<pose::Tracking>(seq % 3);
  r.flags = static_cast<uint8_t>(seq & 3);
  r.quality = static_cast<float>(seq % 100) / 100.0f;
  return r;
}

// A version-1 segment, state running, with the given writer pid and `published`; the slots hold `fill`.
// False when it cannot be made.
inline bool makeSegment(const std::string& name, int64_t writer_pid, uint64_t published, uint32_t capacity = 8,
                        uint8_t fill = 0) {
  ::shm_unlink(name.c_str());
  const int fd = ::shm_open(name.c_str(), O_CREAT | O_EXCL | O_RDWR, 0644);
  if (fd < 0) return false;
  const std::size_t size = pose::shmSegmentSize(capacity);
  void* p = ::ftruncate(fd, static_cast<off_t>(size)) == 0
                ? ::mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0)
                : MAP_FAILED;
  ::close(fd);
  if (p == MAP_FAILED) return false;
  std::memset(static_cast<uint8_t*>(p) + pose::kShmHeaderSize, fill, size - pose::kShmHeaderSize);
  auto& h = *static_cast<pose::ShmHeader*>(p);
  platform::writeShmHeader(h, capacity, writer_pid, 0);
  h.published.store(published);
  ::munmap(p, size);
  return true;
}

// Runs f(header, slots, capacity) on the named segment mapped read-write. False when it cannot be mapped.
template <typename F>
bool editSegment(const std::string& name, F f) {
  const int fd = ::shm_open(name.c_str(), O_RDWR, 0);
  if (fd < 0) return false;
  struct stat st {};
  void* p = ::fstat(fd, &st) == 0
                ? ::mmap(nullptr, static_cast<std::size_t>(st.st_size), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0)
                : MAP_FAILED;
  ::close(fd);
  if (p == MAP_FAILED) return false;
  auto& h = *static_cast<pose::ShmHeader*>(p);
  f(h, reinterpret_cast<pose::ShmSlot*>(static_cast<uint8_t*>(p) + pose::kShmHeaderSize), h.ring_capacity);
  ::munmap(p, static_cast<std::size_t>(st.st_size));
  return true;
}

// The pid of a process that existed and is gone (reaped).
inline pid_t deadPid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return pid;
}

// Truncates the named segment to zero bytes, as its owner (or root) can at any time.
inline bool truncateSegment(const std::string& name) {
  const int fd = ::shm_open(name.c_str(), O_RDWR, 0);
  if (fd < 0) return false;
  const bool ok = ::ftruncate(fd, 0) == 0;
  ::close(fd);
  return ok;
}

}  // namespace mcslam::test
