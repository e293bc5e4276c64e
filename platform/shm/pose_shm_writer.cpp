#include "shm/pose_shm_writer.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdio>
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

// The pid of a running writer that holds `name`, or 0. Read with pread, not mapped: a truncated segment
// then cannot raise SIGBUS here. Our own pid counts as not running: it is a previous incarnation whose pid
// we inherited (pid 1 in a restarted container).
int64_t liveWriterOf(const std::string& name) {
  const int fd = ::shm_open(name.c_str(), O_RDONLY | O_CLOEXEC, 0);
  if (fd < 0) return 0;
  unsigned char bytes[pose::kShmHeaderSize];
  const ssize_t n = ::pread(fd, bytes, sizeof(bytes), 0);
  ::close(fd);
  if (n != static_cast<ssize_t>(sizeof(bytes))) return 0;
  uint32_t magic = 0, state = 0;
  int64_t pid = 0;
  uint64_t start_ticks = 0;
  std::memcpy(&magic, bytes + offsetof(pose::ShmHeader, magic), sizeof(magic));
  std::memcpy(&state, bytes + offsetof(pose::ShmHeader, state), sizeof(state));
  std::memcpy(&pid, bytes + offsetof(pose::ShmHeader, writer_pid), sizeof(pid));
  std::memcpy(&start_ticks, bytes + offsetof(pose::ShmHeader, writer_start_ticks), sizeof(start_ticks));
  const bool running = magic == pose::kShmMagic && state == pose::kWriterRunning;
  return running && pid != ::getpid() && pose::writerProcessRuns(pid, start_ticks) ? pid : 0;
}

// glibc keeps POSIX shared memory in /dev/shm.
std::string ownerOf(const std::string& name) {
  struct stat st {};
  if (::stat(("/dev/shm" + name).c_str(), &st) != 0) return "an unknown user";
  return "uid " + std::to_string(st.st_uid);
}

// Frees the name for a fresh segment, or says who holds it.
void takeOverName(const std::string& name) {
  if (const int64_t pid = liveWriterOf(name))
    throw ResourceBusyError("publish.shm.name: '" + name + "' is in use by a running mcslamd (pid " +
                            std::to_string(pid) + "); stop it or give this daemon another name");
  if (::shm_unlink(name.c_str()) == 0 || errno == ENOENT) return;  // old readers keep the old segment
  if (errno == EPERM || errno == EACCES)
    throw ResourceBusyError("publish.shm.name: '" + name + "' exists and belongs to " + ownerOf(name) +
                            ", which this daemon (uid " + std::to_string(::getuid()) +
                            ") may not remove; remove it as that user or root, or choose another name");
  throw InputError("publish.shm.name: shm_unlink('" + name + "'): " + std::strerror(errno));
}
}  // namespace

std::string shmModeProblem(unsigned mode) {
  char text[8];
  std::snprintf(text, sizeof(text), "%04o", mode);
  if (mode & 022)
    return std::string("'") + text +
           "' lets group or others write (and truncate) the segment; readers need only read, e.g. \"0644\"";
  if ((mode & 0600) != 0600) return std::string("'") + text + "' must let the owner read and write (0600)";
  return {};
}

PoseShmWriter::PoseShmWriter(const std::string& name, uint32_t ring_capacity, unsigned mode)
    : name_(name), capacity_(ring_capacity) {
  if (name.size() < 2 || name[0] != '/' || name.find('/', 1) != std::string::npos)
    throw InputError("publish.shm.name: '" + name + "' must be '/' followed by a name without '/'");
  if (ring_capacity == 0) throw InputError("publish.shm.ring_length: must be at least 1");
  if (const std::string why = shmModeProblem(mode); !why.empty()) throw InputError("publish.shm.mode: " + why);
  takeOverName(name);
  create(mode);
  initHeader();
}

void PoseShmWriter::create(unsigned mode) {
  const int fd = ::shm_open(name_.c_str(), O_CREAT | O_EXCL | O_RDWR | O_CLOEXEC, mode);
  if (fd < 0 && errno == EEXIST)
    throw ResourceBusyError("publish.shm.name: '" + name_ + "' was created by " + ownerOf(name_) +
                            " while this daemon was starting");
  if (fd < 0) throw InputError("publish.shm.name: shm_open('" + name_ + "'): " + std::strerror(errno));
  size_ = pose::shmSegmentSize(capacity_);
  struct stat st {};
  if (::fchmod(fd, mode) != 0 || ::ftruncate(fd, static_cast<off_t>(size_)) != 0 || ::fstat(fd, &st) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    ::shm_unlink(name_.c_str());
    throw InputError("publish.shm: cannot size or chmod '" + name_ + "': " + why);
  }
  dev_ = st.st_dev;
  ino_ = st.st_ino;
  void* p = ::mmap(nullptr, size_, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  if (p == MAP_FAILED) {
    ::shm_unlink(name_.c_str());
    throw InputError("publish.shm: mmap('" + name_ + "'): " + std::strerror(errno));
  }
  base_ = static_cast<uint8_t*>(p);
  // Whoever may truncate the segment (its owner, root) must not be able to end the daemon with SIGBUS.
  pose::shm_guard::install();
  guard_ = pose::shm_guard::add(base_, size_, PROT_READ | PROT_WRITE);
}

void writeShmHeader(pose::ShmHeader& h, uint32_t ring_capacity, int64_t writer_pid, uint64_t writer_start_ticks) {
  h.version = pose::kShmVersion;
  h.header_size = pose::kShmHeaderSize;
  h.record_size = pose::kPacketSize;
  h.slot_size = pose::kShmSlotSize;
  h.ring_capacity = ring_capacity;
  h.ring_offset = pose::kShmHeaderSize + pose::kShmSlotSize;
  h.writer_pid = writer_pid;
  h.writer_start_ticks = writer_start_ticks;
  h.start_time_ns = realtimeNs();
  h.state.store(pose::kWriterRunning, std::memory_order_relaxed);
  h.published.store(0, std::memory_order_relaxed);
  h.magic.store(pose::kShmMagic, std::memory_order_release);  // last: the header is complete
}

void PoseShmWriter::initHeader() {
  std::memset(base_, 0, size_);  // also faults every page in now, not on the first pose
  writeShmHeader(header(), capacity_, ::getpid(), pose::processStartTicks(static_cast<long>(::getpid())));
}

PoseShmWriter::~PoseShmWriter() {
  markStopped();
  pose::shm_guard::remove(guard_);
  if (base_) ::munmap(base_, size_);
}

void PoseShmWriter::publish(const pose::PoseRecord& record) {
  uint8_t bytes[pose::kPacketSize];
  pose::encodePacket(record, bytes);
  // Our own offsets, not the header's: the segment's owner could rewrite the header.
  constexpr std::size_t kRing = pose::kShmHeaderSize + pose::kShmSlotSize;
  pose::seqlockWrite(slot(kRing + (record.sequence % capacity_) * pose::kShmSlotSize), bytes);
  pose::seqlockWrite(slot(pose::kShmHeaderSize), bytes);
  header().published.store(record.sequence, std::memory_order_release);
}

void PoseShmWriter::markStopped() {
  if (!base_ || unlinked_) return;
  header().state.store(pose::kWriterStopped, std::memory_order_release);
  unlinked_ = true;
  // Another writer may have the name by now (someone unlinked ours and started one): leave its segment.
  const int fd = ::shm_open(name_.c_str(), O_RDONLY | O_CLOEXEC, 0);
  if (fd < 0) return;
  struct stat st {};
  const bool ours = ::fstat(fd, &st) == 0 && st.st_dev == dev_ && st.st_ino == ino_;
  ::close(fd);
  if (ours) ::shm_unlink(name_.c_str());
}

}  // namespace mcslam::platform
