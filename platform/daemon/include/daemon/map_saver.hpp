#pragma once
// Saving the place map while the daemon runs: every `interval`, between two frames, the processing thread has the
// processor write its map file into a buffer sized at start (no allocation), and the saver's own thread writes it
// to disk whole or not at all (writeFileSynced), so a slow or full disk never holds up a frame. A save is skipped
// while the previous one is still being written. A failed save (disk full) is logged and counted; the previous
// map file stays as it was, and the next interval tries again.
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include "mcslam/core/synced_file.hpp"
#include "mcslam/pipeline/frame_processor.hpp"
#include "realtime/alloc_meter.hpp"

namespace mcslam::platform {

class MapSaver {
 public:
  // `interval_s` 0: only saveNow().
  MapSaver(std::string path, double interval_s, std::size_t max_bytes);
  ~MapSaver();
  MapSaver(const MapSaver&) = delete;
  MapSaver& operator=(const MapSaver&) = delete;

  void start();
  // On the processing thread, after a frame.
  void afterFrame(const FrameProcessor& processor, int64_t now_ns);
  // At a clean stop, with the processing finished: the last map, on disk when it returns; then the thread ends.
  void saveNow(const FrameProcessor& processor);

  const std::string& path() const { return target_.path; }
  uint64_t saves() const { return saves_.load(std::memory_order_relaxed); }
  uint64_t failures() const { return failures_.load(std::memory_order_relaxed); }
  // Of the saver's thread, after its first save (which warms up the file system's paths).
  uint64_t allocationsSinceWarmup() const { return meter_.since(); }

 private:
  void loop();
  bool write();  // the buffer to the file, on the calling thread

  SyncedFileTarget target_;
  int64_t interval_ns_;
  std::string buffer_;
  int64_t last_ns_ = 0;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool pending_ = false, stop_ = false;  // under mutex_
  std::atomic<bool> busy_{false};        // the buffer belongs to the saver's thread
  std::thread thread_;
  std::atomic<uint64_t> saves_{0}, failures_{0};
  ThreadAllocMeter meter_;
};

}  // namespace mcslam::platform
