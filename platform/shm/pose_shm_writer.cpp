#include "shm/pose_shm_writer.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>

#include "mcslam/core/error.hpp"

namespace mcslam::platform {

namespace {
int64_t realtimeNs() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}
}  // namespace

PoseShmWriter::PoseShmWriter(const std::string& name, uint32_t ring_capacity, unsigned mode)
    : name_(name), capacity_(ring_capacity) {
  if (name.size() < 2 || name[0] != '/' || name.find('/', 1) != std::string::npos)
    throw InputError("publish.shm.name: '" + name + "' must be '/' followed by a name without '/'");
  if (ring_capacity == 0) throw InputError("publish.shm.ring_length: must be at least 1");
  ::shm_unlink(name.c_str());  // a fresh segment: old readers keep the old one
  const int fd = ::shm_open(name.c_str(), O_CREAT | O_EXCL | O_RDWR | O_CLOEXEC, mode);
  if (fd < 0) throw InputError("publish.shm.name: shm_open('" + name + "'): " + std::strerror(errno));
  size_ = pose::shmSegmentSize(ring_capacity);
  if (::fchmod(fd, mode) != 0 || ::ftruncate(fd, static_cast<off_t>(size_)) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    ::shm_unlink(name.c_str());
    throw InputError("publish.shm: cannot size or chmod '" + name + "': " + why);
  }
  void* p = ::mmap(nullptr, size_, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  if (p == MAP_FAILED) {
    ::shm_unlink(name.c_str());
    throw InputError("publish.shm: mmap('" + name + "'): " + std::strerror(errno));
  }
  base_ = static_cast<uint8_t*>(p);
  std::memset(base_, 0, size_);  // also faults every page in now, not on the first pose
  pose::ShmHeader& h = header();
  h.version = pose::kShmVersion;
  h.header_size = pose::kShmHeaderSize;
  h.record_size = pose::kPacketSize;
  h.slot_size = pose::kShmSlotSize;
  h.ring_capacity = ring_capacity;
  h.ring_offset = pose::kShmHeaderSize + pose::kShmSlotSize;
  h.writer_pid = ::getpid();
  h.start_time_ns = realtimeNs();
  h.state.store(pose::kWriterRunning, std::memory_order_relaxed);
  h.published.store(0, std::memory_order_relaxed);
  h.magic.store(pose::kShmMagic, std::memory_order_release);  // last: the header is complete
}

PoseShmWriter::~PoseShmWriter() {
  markStopped();
  if (base_) ::munmap(base_, size_);
}

void PoseShmWriter::publish(const pose::PoseRecord& record) {
  uint8_t bytes[pose::kPacketSize];
  pose::encodePacket(record, bytes);
  pose::seqlockWrite(slot(header().ring_offset + (record.sequence % capacity_) * pose::kShmSlotSize), bytes);
  pose::seqlockWrite(slot(pose::kShmHeaderSize), bytes);
  header().published.store(record.sequence, std::memory_order_release);
}

void PoseShmWriter::markStopped() {
  if (!base_ || unlinked_) return;
  header().state.store(pose::kWriterStopped, std::memory_order_release);
  ::shm_unlink(name_.c_str());
  unlinked_ = true;
}

}  // namespace mcslam::platform
