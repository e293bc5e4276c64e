#pragma once
// Appends poses to a TUM trajectory file ("t tx ty tz qx qy qz qw", t in seconds with nine decimals,
// numbers in shortest round-trip form so a reader gets the published doubles back exactly). Each pose
// is written with one write(2) as it is published, so a crash loses nothing already written; close()
// fsyncs. No allocation per pose.
#include <atomic>
#include <string>

#include "mcslam/pose_protocol.hpp"

namespace mcslam::platform {

class TrajectoryWriter {
 public:
  // Creates (truncates) the file; an existing non-empty file is first renamed to "<path>.previous".
  // Throws InputError naming output.directory / output.trajectory and the path when it cannot.
  explicit TrajectoryWriter(const std::string& path);
  ~TrajectoryWriter() { close(); }
  TrajectoryWriter(const TrajectoryWriter&) = delete;
  TrajectoryWriter& operator=(const TrajectoryWriter&) = delete;

  bool append(const pose::PoseRecord& r);
  // Flushes to disk (fsync). Returns false when that failed.
  bool sync();
  void close();
  const std::string& path() const { return path_; }
  uint64_t written() const { return written_.load(std::memory_order_relaxed); }
  uint64_t errors() const { return errors_.load(std::memory_order_relaxed); }

 private:
  std::string path_;
  int fd_ = -1;
  std::atomic<uint64_t> written_{0}, errors_{0};
};

// One TUM line for the record (with '\n'); returns its length. `out` must hold 256 bytes.
int formatTumLine(const pose::PoseRecord& r, char* out);

}  // namespace mcslam::platform
