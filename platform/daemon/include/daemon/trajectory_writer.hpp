#pragma once
// Appends poses to a TUM trajectory file ("t tx ty tz qx qy qz qw", t in seconds with nine decimals,
// numbers in shortest round-trip form so a reader gets the published doubles back exactly). Each pose
// is written with one write(2) as it is published, so a crash loses nothing already written; close()
// fsyncs. No allocation per pose.
// A write that fails (disk full, a size limit, an I/O error) is counted and the file is cut back to its last whole
// line, so that it never holds a torn line and the next pose that can be written starts a line of its own. A file
// removed while it is written is noticed at the next pose and made again at the same path (if its folder is gone,
// every pose until it is back counts as an error).
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

  // False when the pose could not be written (counted in errors(), the reason in lastErrno()).
  bool append(const pose::PoseRecord& r);
  // Flushes to disk (fsync). Returns false when that failed.
  bool sync();
  void close();
  const std::string& path() const { return path_; }
  uint64_t written() const { return written_.load(std::memory_order_relaxed); }
  uint64_t errors() const { return errors_.load(std::memory_order_relaxed); }  // poses not written, failed syncs
  int lastErrno() const { return last_errno_.load(std::memory_order_relaxed); }
  uint64_t reopened() const { return reopened_.load(std::memory_order_relaxed); }  // made again after a removal

 private:
  bool openFile(int flags);  // at path_, with the header; false (errno kept) when it cannot
  bool ensureFileExists();
  bool writeAll(const char* bytes, int n);  // false with errno set
  void fail(int err);

  std::string path_;
  int fd_ = -1;
  off_t whole_lines_size_ = 0;  // the file's size up to its last whole line
  std::atomic<uint64_t> written_{0}, errors_{0}, reopened_{0};
  std::atomic<int> last_errno_{0};
};

// One TUM line for the record (with '\n'); returns its length. `out` must hold 256 bytes.
int formatTumLine(const pose::PoseRecord& r, char* out);

}  // namespace mcslam::platform
