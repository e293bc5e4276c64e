#pragma once
// Creates the shared-memory pose segment (layout in include/mcslam/pose_shm.hpp) and publishes into
// it. Single writer: the daemon's publisher thread. publish() neither allocates nor blocks.
#include <sys/types.h>

#include <stdexcept>
#include <string>

#include "mcslam/pose_shm.hpp"

namespace mcslam::platform {

// A resource that another process or user holds (here the shared-memory name). Not the input's fault: a later
// attempt may succeed once it is released, so mcslamd exits with a status that systemd restarts (3, not 2).
class ResourceBusyError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class PoseShmWriter {
 public:
  // Creates a fresh segment. One left by a writer that no longer runs (a crash) is replaced: its readers
  // see check() = WriterGone, then Replaced. Throws ResourceBusyError naming the name and the holder when a
  // running writer has it (its pid) or another user owns it (its uid); InputError for a bad name or mode
  // and other failures.
  PoseShmWriter(const std::string& name, uint32_t ring_capacity, unsigned mode);
  ~PoseShmWriter();
  PoseShmWriter(const PoseShmWriter&) = delete;
  PoseShmWriter& operator=(const PoseShmWriter&) = delete;

  // Writes the record into the ring and the latest slot, then advances `published` (release).
  // record.sequence must be the previous one + 1, starting at 1.
  void publish(const pose::PoseRecord& record);
  // True once someone truncated the segment: publish() then writes into private zero pages, readers see
  // nothing more. The owner makes a new writer.
  bool lost() const { return pose::shm_guard::lost(guard_); }
  // Marks the segment stopped (readers see it); unlinks the name if it still leads to this segment.
  void markStopped();
  const std::string& name() const { return name_; }

 private:
  void create(unsigned mode);
  void initHeader();
  pose::ShmHeader& header() { return *reinterpret_cast<pose::ShmHeader*>(base_); }
  pose::ShmSlot& slot(std::size_t offset) { return *reinterpret_cast<pose::ShmSlot*>(base_ + offset); }

  std::string name_;
  uint8_t* base_ = nullptr;
  std::size_t size_ = 0;
  uint32_t capacity_ = 0;
  dev_t dev_ = 0;  // identity of our segment, so that we never unlink another writer's
  ino_t ino_ = 0;
  int guard_ = -1;
  bool unlinked_ = false;
};

// The part of publish.shm.mode a writer refuses: readers never write, so neither group nor others need
// write permission (with it any local user could truncate the segment), and the owner maps it read-write.
// Empty when the mode is fine, else the reason.
std::string shmModeProblem(unsigned mode);

// Fills a zeroed segment's header: a ring of `ring_capacity` slots written by process `writer_pid` (which started
// at `writer_start_ticks`, 0 = not recorded), state running, nothing published; the magic last, with release, so
// that a reader that sees it sees the whole header. The writer's, and the tests' segments made by hand.
void writeShmHeader(pose::ShmHeader& h, uint32_t ring_capacity, int64_t writer_pid, uint64_t writer_start_ticks);

}  // namespace mcslam::platform
