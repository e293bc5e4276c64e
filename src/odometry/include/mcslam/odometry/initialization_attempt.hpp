#pragma once
// A two-frame initialization attempt (Initializer::feed) taken off the frame's thread: its matching and
// relative-pose RANSAC cost more than tracking a frame, and a rig that starts from two frames makes one per frame
// until it succeeds. The attempt of frame k runs beside the next frame's front-end and is taken at frame k + 1 (waiting
// for it if it is not done), so what follows never depends on the thread's timing: a map that starts from it starts at
// frame k, seen from frame k + 1, which is then tracked on it. Without a thread the attempt runs at once, with the same
// result.
#include <cstdint>
#include <memory>
#include <thread>

#include "mcslam/core/background_task.hpp"
#include "mcslam/features/frame_features.hpp"
#include "mcslam/odometry/initializer.hpp"

namespace mcslam {

class InitializationAttempt {
 public:
  // `on_thread`: run attempts on a thread of their own (made here, the only allocation).
  InitializationAttempt(Initializer& initializer, int cameras, int max_features_per_camera, bool on_thread);
  ~InitializationAttempt();
  InitializationAttempt(const InitializationAttempt&) = delete;
  InitializationAttempt& operator=(const InitializationAttempt&) = delete;

  // Starts an attempt with a copy of the frame; the initializer is the attempt's until collect() or cancel().
  void submit(const FrameFeatures& frame, uint64_t frame_index);
  bool pending() const { return pending_; }
  // Waits for the pending attempt and returns its result (Ready: T_ref_cur as Initializer::feed sets it).
  Initializer::TwoFrame collect(SE3& T_ref_cur);
  // Waits for an attempt in flight and drops it; the initializer keeps what that attempt did to it (reset it).
  void cancel();
  // The frame of the last attempt submitted, and its index (read them when no attempt is pending).
  const FrameFeatures& frame() const { return job_.frame; }
  uint64_t frameIndex() const { return job_.frame_index; }
  // The thread the last attempt ran on (tests: the caller's only without a thread of its own; not while pending).
  std::thread::id lastThread() const { return job_.thread; }
  // Heap allocations made on the attempts' thread so far (0 without one).
  uint64_t threadAllocations() const { return task_ ? task_->allocations() : 0; }

 private:
  struct FeedJob final : BackgroundJob {
    void run() override {
      thread = std::this_thread::get_id();
      result = initializer->feed(frame, frame_index, T_ref_cur);
    }
    Initializer* initializer = nullptr;
    FrameFeatures frame;
    uint64_t frame_index = 0;
    SE3 T_ref_cur;
    Initializer::TwoFrame result = Initializer::TwoFrame::Waiting;
    std::thread::id thread;
  };
  FeedJob job_;
  bool pending_ = false;
  std::unique_ptr<BackgroundTask> task_;  // last: stops before the job goes; null: attempts run at once
};

}  // namespace mcslam
