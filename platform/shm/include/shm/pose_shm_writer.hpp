#pragma once
// Creates the shared-memory pose segment (layout in include/mcslam/pose_shm.hpp) and publishes into
// it. Single writer: the daemon's publisher thread. publish() neither allocates nor blocks.
#include <string>

#include "mcslam/pose_shm.hpp"

namespace mcslam::platform {

class PoseShmWriter {
 public:
  // Replaces any segment of that name (readers of a previous run keep their old mapping, which says
  // "stopped"). Throws InputError naming the shm name and the reason when it cannot.
  PoseShmWriter(const std::string& name, uint32_t ring_capacity, unsigned mode);
  ~PoseShmWriter();
  PoseShmWriter(const PoseShmWriter&) = delete;
  PoseShmWriter& operator=(const PoseShmWriter&) = delete;

  // Writes the record into the ring and the latest slot, then advances `published` (release).
  // record.sequence must be the previous one + 1, starting at 1.
  void publish(const pose::PoseRecord& record);
  // Marks the segment stopped (readers see it); the name is unlinked.
  void markStopped();
  const std::string& name() const { return name_; }

 private:
  pose::ShmHeader& header() { return *reinterpret_cast<pose::ShmHeader*>(base_); }
  pose::ShmSlot& slot(std::size_t offset) { return *reinterpret_cast<pose::ShmSlot*>(base_ + offset); }

  std::string name_;
  uint8_t* base_ = nullptr;
  std::size_t size_ = 0;
  uint32_t capacity_ = 0;
  bool unlinked_ = false;
};

}  // namespace mcslam::platform
