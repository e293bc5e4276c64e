#pragma once
// Shared-memory segments made by hand for the tests of the pose segment's reader, writer and echo tool: a
// header saying what the test needs (a writer pid that is alive or dead, a `published` no slot backs).
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>

#include "mcslam/pose_shm.hpp"

namespace mcslam::test {

inline std::string uniqueShmName(const char* tag) {
  return std::string("/mcslam-test-") + tag + "-" + std::to_string(::getpid());
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
  h.version = pose::kShmVersion;
  h.header_size = pose::kShmHeaderSize;
  h.record_size = pose::kPacketSize;
  h.slot_size = pose::kShmSlotSize;
  h.ring_capacity = capacity;
  h.ring_offset = pose::kShmHeaderSize + pose::kShmSlotSize;
  h.writer_pid = writer_pid;
  h.state.store(pose::kWriterRunning);
  h.published.store(published);
  h.magic.store(pose::kShmMagic);
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
