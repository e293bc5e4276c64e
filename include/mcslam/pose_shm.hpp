#pragma once
// The shared-memory pose segment of mcslamd and a read-only consumer for it (header-only, POSIX).
//
// Layout (docs/pose-protocol.md, "shared memory"): a 128-byte header, the latest pose in one 128-byte
// slot, then a ring of the last N poses in 128-byte slots. Every slot holds a sequence word and the
// 104-byte pose record of pose_protocol.hpp, copied as 13 64-bit words.
//
// Consistency: each slot is a seqlock. The single writer makes the sequence word odd, writes the
// words, then makes it even with a release store; a reader loads the sequence with acquire, copies
// the words with relaxed atomic loads, issues an acquire fence and re-reads the sequence. Equal and
// even means the copy is whole. This is correct under the C++ memory model, so on ARM as well as x86
// (Boehm, "Can seqlocks get along with programming language memory models?", 2012). The segment is
// mapped read-only: a reader only loads.
//
// A writer that crashes leaves its segment saying "running"; the restarted writer makes a new one under
// the same name. check() tells a reader which case it is in, reattach() follows the name.
#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "mcslam/pose_protocol.hpp"
#include "mcslam/pose_shm_guard.hpp"

namespace mcslam::pose {

inline constexpr uint32_t kShmMagic = 0x4D53434Du;  // bytes 'M' 'C' 'S' 'M' in host order
inline constexpr uint16_t kShmVersion = 1;
inline constexpr std::size_t kShmHeaderSize = 128;
inline constexpr std::size_t kShmSlotSize = 128;
inline constexpr std::size_t kRecordWords = kPacketSize / 8;  // 13
inline constexpr uint32_t kWriterRunning = 1, kWriterStopped = 2;

struct alignas(64) ShmSlot {
  std::atomic<uint64_t> seq;  // odd while the writer is inside
  std::atomic<uint64_t> words[kRecordWords];
  uint64_t reserved[2];
};

// Host byte order (writer and readers share the machine).
struct alignas(64) ShmHeader {
  std::atomic<uint32_t> magic;  // stored last, with release, once the header is complete
  uint16_t version;
  uint16_t header_size;         // 128: offset of the latest-pose slot
  uint32_t record_size;         // 104
  uint32_t slot_size;           // 128
  uint32_t ring_capacity;       // N
  std::atomic<uint32_t> state;  // kWriterRunning, kWriterStopped
  uint64_t ring_offset;         // 256: offset of ring slot 0
  int64_t writer_pid;
  int64_t start_time_ns;            // CLOCK_REALTIME when the writer created the segment
  std::atomic<uint64_t> published;  // sequence of the newest pose (0 = none yet)
  uint64_t writer_start_ticks;      // the writer's start, /proc/<pid>/stat field 22 (0 = not recorded)
  uint64_t reserved[8];
};

static_assert(sizeof(ShmSlot) == kShmSlotSize);
static_assert(sizeof(ShmHeader) == kShmHeaderSize);
static_assert(std::atomic<uint64_t>::is_always_lock_free, "the seqlock needs lock-free 64-bit atomics");
static_assert(std::atomic<uint32_t>::is_always_lock_free);

inline std::size_t shmSegmentSize(uint32_t ring_capacity) {
  return kShmHeaderSize + kShmSlotSize + static_cast<std::size_t>(ring_capacity) * kShmSlotSize;
}

// Reads one slot under its seqlock. False when no whole copy was obtained within max_spins tries
// (a writer that died inside the slot leaves it odd forever; a reader must not hang on it).
inline bool seqlockRead(const ShmSlot& slot, uint8_t out[kPacketSize], int max_spins = 100000) {
  uint64_t words[kRecordWords];
  for (int spin = 0; spin < max_spins; ++spin) {
    const uint64_t s1 = slot.seq.load(std::memory_order_acquire);
    if (s1 & 1u) continue;
    for (std::size_t w = 0; w < kRecordWords; ++w) words[w] = slot.words[w].load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    const uint64_t s2 = slot.seq.load(std::memory_order_relaxed);
    if (s1 == s2) {
      std::memcpy(out, words, kPacketSize);
      return s1 != 0;  // 0 = never written
    }
  }
  return false;
}

// The writer's half (used by mcslamd; here so both halves sit side by side).
inline void seqlockWrite(ShmSlot& slot, const uint8_t in[kPacketSize]) {
  uint64_t words[kRecordWords];
  std::memcpy(words, in, kPacketSize);
  const uint64_t s = slot.seq.load(std::memory_order_relaxed);
  slot.seq.store(s + 1, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);  // the odd value is visible before any word
  for (std::size_t w = 0; w < kRecordWords; ++w) slot.words[w].store(words[w], std::memory_order_relaxed);
  slot.seq.store(s + 2, std::memory_order_release);
}

enum class ReadStatus { Ok, NotYet, Overwritten, Busy };

// When process `pid` started, in clock ticks after boot (/proc/<pid>/stat, field 22); 0 when it cannot be read.
// Unlike the pid, which the kernel hands out again, it tells a process from a later one of the same pid. No
// allocation. Read relative to /proc's directory: qemu-user rewrites a process's absolute /proc/<own pid>/stat
// with a start of its own making, so a writer under it would record a start that its readers never see.
inline uint64_t processStartTicks(long pid) {
  char path[32];
  std::snprintf(path, sizeof(path), "%ld/stat", pid);
  const int proc = ::open("/proc", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (proc < 0) return 0;
  const int fd = ::openat(proc, path, O_RDONLY | O_CLOEXEC);
  ::close(proc);
  if (fd < 0) return 0;
  char text[1024];
  const ssize_t n = ::read(fd, text, sizeof(text) - 1);
  ::close(fd);
  if (n <= 0) return 0;
  text[n] = '\0';
  const char* p = std::strrchr(text, ')');  // the end of the command name, which may hold spaces
  if (!p) return 0;
  for (int field = 2; field < 22; ++p) {  // a space before each field after the name (field 2)
    if (*p == '\0') return 0;
    if (*p == ' ') ++field;
  }
  return std::strtoull(p, nullptr, 10);
}

// Whether the writer of a header with this pid and start still runs: the pid exists and, when the writer recorded
// its start, belongs to that same process, not to a later one that got the pid after a crash. Where /proc does not
// show the process (another pid namespace), the pid alone decides.
inline bool writerProcessRuns(int64_t pid, uint64_t start_ticks) {
  if (pid <= 0 || pid != static_cast<pid_t>(pid)) return false;
  if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) return false;
  if (start_ticks == 0) return true;
  const uint64_t now = processStartTicks(static_cast<long>(pid));
  return now == 0 || now == start_ticks;
}

// What check() found (docs/pose-protocol.md, "staying attached").
enum class SegmentStatus {
  Live,        // the writer runs and the name still leads to this segment
  Stopped,     // the writer stopped cleanly (state = stopped)
  WriterGone,  // the writer process no longer exists (it crashed or was killed)
  Replaced,    // the name now leads to another segment (a restarted writer): reattach()
  NameGone,    // the name was removed and nothing replaced it (yet)
  Truncated,   // someone shrank the segment: its contents are gone
  NotOpen,
};
const char* segmentStatusName(SegmentStatus s);

class PoseShmReader {
 public:
  PoseShmReader() = default;
  PoseShmReader(const PoseShmReader&) = delete;
  PoseShmReader& operator=(const PoseShmReader&) = delete;
  ~PoseShmReader() { close(); }

  // Makes a truncated segment read as zeros (check() then says Truncated) instead of ending the process
  // with SIGBUS: installs a process-wide SIGBUS handler (pose_shm_guard.hpp). Call once, before reading.
  static bool guardAgainstTruncation() { return shm_guard::install(); }

  // Maps the segment read-only. False (and *error) when it is missing, too small or not a version-1
  // mcslam pose segment.
  bool open(const std::string& name, std::string* error = nullptr) {
    close();
    const int fd = ::shm_open(name.c_str(), O_RDONLY | O_CLOEXEC, 0);
    if (fd < 0) return fail(error, "shm_open(" + name + "): " + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd, &st) != 0 || static_cast<std::size_t>(st.st_size) < shmSegmentSize(0)) {
      ::close(fd);
      return fail(error, name + ": segment too small (the writer may still be creating it)");
    }
    void* p = ::mmap(nullptr, static_cast<std::size_t>(st.st_size), PROT_READ, MAP_SHARED, fd, 0);
    if (p == MAP_FAILED) {
      ::close(fd);
      return fail(error, "mmap(" + name + "): " + std::strerror(errno));
    }
    base_ = static_cast<const uint8_t*>(p);
    size_ = static_cast<std::size_t>(st.st_size);
    fd_ = fd;
    dev_ = st.st_dev;
    ino_ = st.st_ino;
    guard_ = shm_guard::add(base_, size_, PROT_READ);
    name_ = name;
    return validate(error);
  }

  // Opens the segment the name leads to now (after Replaced, WriterGone or NameGone).
  bool reattach(std::string* error = nullptr) {
    const std::string name = name_;
    return open(name, error);
  }

  void close() {
    shm_guard::remove(guard_);
    guard_ = -1;
    if (base_) ::munmap(const_cast<uint8_t*>(base_), size_);
    if (fd_ >= 0) ::close(fd_);
    base_ = nullptr;
    size_ = 0;
    fd_ = -1;
  }
  bool isOpen() const { return base_ != nullptr; }
  const std::string& name() const { return name_; }

  // Whether this segment is still the one to read: a few system calls (fstat, kill(pid, 0), shm_open,
  // fstat, close), no allocation. Call it now and then, e.g. when no new pose came for a while.
  SegmentStatus check() const {
    if (!isOpen()) return SegmentStatus::NotOpen;
    struct stat st {};
    if (shm_guard::lost(guard_) || (::fstat(fd_, &st) == 0 && static_cast<std::size_t>(st.st_size) < size_))
      return SegmentStatus::Truncated;
    if (header().state.load(std::memory_order_acquire) == kWriterStopped) return SegmentStatus::Stopped;
    // The name first: a restarted writer made a new segment, whatever became of the old writer's pid.
    const int fd = ::shm_open(name_.c_str(), O_RDONLY | O_CLOEXEC, 0);
    if (fd < 0 && errno == ENOENT) return SegmentStatus::NameGone;
    if (fd < 0 && errno == EACCES) return SegmentStatus::Replaced;  // another user's file now
    if (fd >= 0) {  // (EMFILE and the like tell nothing about the segment)
      const bool same = ::fstat(fd, &st) == 0 && st.st_dev == dev_ && st.st_ino == ino_;
      ::close(fd);
      if (!same) return SegmentStatus::Replaced;
    }
    if (!writerProcessRuns(writerPid(), header().writer_start_ticks)) return SegmentStatus::WriterGone;
    return SegmentStatus::Live;
  }

  const ShmHeader& header() const { return *reinterpret_cast<const ShmHeader*>(base_); }
  uint32_t ringCapacity() const { return capacity_; }
  uint64_t published() const { return header().published.load(std::memory_order_acquire); }
  bool writerRunning() const { return header().state.load(std::memory_order_acquire) == kWriterRunning; }
  int64_t writerPid() const { return header().writer_pid; }

  // The newest pose.
  ReadStatus readLatest(PoseRecord& out) const {
    uint8_t bytes[kPacketSize];
    if (published() == 0) return ReadStatus::NotYet;
    if (!seqlockRead(latestSlot(), bytes)) return ReadStatus::Busy;
    return decodePacket(bytes, kPacketSize, out) == DecodeStatus::Ok ? ReadStatus::Ok : ReadStatus::Busy;
  }

  // The pose with publish sequence `seq` (1-based), while it is still in the ring.
  ReadStatus readSequence(uint64_t seq, PoseRecord& out) const {
    const uint64_t newest = published();
    if (seq == 0 || seq > newest) return ReadStatus::NotYet;
    if (newest - seq >= ringCapacity()) return ReadStatus::Overwritten;
    uint8_t bytes[kPacketSize];
    if (!seqlockRead(ringSlot(seq), bytes)) {
      // A slot never written although `published` covers it: this segment never had the record (a writer
      // that made a new segment mid-run goes on with its sequence).
      return ringSlot(seq).seq.load(std::memory_order_acquire) == 0 ? ReadStatus::Overwritten : ReadStatus::Busy;
    }
    if (decodePacket(bytes, kPacketSize, out) != DecodeStatus::Ok) return ReadStatus::Busy;
    return out.sequence == seq ? ReadStatus::Ok : ReadStatus::Overwritten;
  }

  const ShmSlot& latestSlot() const { return *reinterpret_cast<const ShmSlot*>(base_ + kShmHeaderSize); }
  // Offsets from the header as validated at open: a header rewritten later cannot lead outside the mapping.
  const ShmSlot& ringSlot(uint64_t seq) const {
    return *reinterpret_cast<const ShmSlot*>(base_ + kShmHeaderSize + kShmSlotSize + (seq % capacity_) * kShmSlotSize);
  }

 private:
  bool validate(std::string* error) {
    const ShmHeader& h = header();
    if (h.magic.load(std::memory_order_acquire) != kShmMagic)
      return failClose(error, name_ + ": not an mcslam pose segment (magic)");
    if (h.version != kShmVersion) return failClose(error, name_ + ": unsupported version " + std::to_string(h.version));
    if (h.record_size != kPacketSize || h.slot_size != kShmSlotSize || h.header_size != kShmHeaderSize ||
        h.ring_offset != kShmHeaderSize + kShmSlotSize || shmSegmentSize(h.ring_capacity) > size_ ||
        h.ring_capacity == 0)
      return failClose(error, name_ + ": inconsistent header");
    capacity_ = h.ring_capacity;
    return true;
  }
  static bool fail(std::string* error, const std::string& why) {
    if (error) *error = why;
    return false;
  }
  bool failClose(std::string* error, const std::string& why) {
    close();
    return fail(error, why);
  }

  const uint8_t* base_ = nullptr;
  std::size_t size_ = 0;
  uint32_t capacity_ = 1;
  int fd_ = -1;
  dev_t dev_ = 0;
  ino_t ino_ = 0;
  int guard_ = -1;
  std::string name_;
};

inline const char* segmentStatusName(SegmentStatus s) {
  switch (s) {
    case SegmentStatus::Live: return "live";
    case SegmentStatus::Stopped: return "stopped";
    case SegmentStatus::WriterGone: return "writer gone";
    case SegmentStatus::Replaced: return "replaced";
    case SegmentStatus::NameGone: return "name gone";
    case SegmentStatus::Truncated: return "truncated";
    case SegmentStatus::NotOpen: return "not open";
  }
  return "?";
}

}  // namespace mcslam::pose
