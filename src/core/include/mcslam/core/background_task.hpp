#pragma once
// One job at a time on a thread of its own, for work that must not hold up a frame (the sliding-window solve, the
// loop closer's pose graph). The owner hands a job over and goes on; it takes the job's result at a point of its
// choosing, after wait() or once ready() says the job is done, so that what it does with the result depends on
// thread timing only where the owner wants it to.
#include <atomic>
#include <cstdint>

#include "mcslam/core/worker_pool.hpp"

namespace mcslam {

class BackgroundJob {
 public:
  virtual void run() = 0;  // on the task's thread; must not throw

 protected:
  ~BackgroundJob() = default;
};

// What every task's thread runs once, before its first job (nullptr: nothing). The platform layer sets it to
// lower the scheduling class of the background threads, so that a job woken by the frame's thread does not preempt
// that thread while it still works on the frame; the core itself does not touch the OS. Process-wide; set it
// before the first job starts.
using BackgroundThreadSetup = void (*)();
void setBackgroundThreadSetup(BackgroundThreadSetup setup);

class BackgroundTask {
 public:
  BackgroundTask() = default;  // starts the thread (the only allocation)
  BackgroundTask(const BackgroundTask&) = delete;
  BackgroundTask& operator=(const BackgroundTask&) = delete;

  // Waits for the job started last, then starts `job`, which the owner must not touch until the job is collected
  // (or waited for) and which must outlive this task.
  void start(BackgroundJob& job);
  // A job was started and not collected since.
  bool running() const { return running_; }
  // The job started last has finished: wait() would return at once. Does not block.
  bool ready() { return !running_ || pool_.idle(); }
  // Blocks until the job started last has finished (at once when none runs).
  void wait() const { pool_.wait(); }
  // wait(), and the job is no longer running(); false when none was started since the last collect().
  bool collect();

  // Heap allocations made on the task's thread by all jobs so far, and the time the last finished job took; any
  // thread may read them at any time.
  uint64_t allocations() const { return runner_.allocations.load(std::memory_order_relaxed); }
  double lastMilliseconds() const { return runner_.milliseconds.load(std::memory_order_relaxed); }

 private:
  struct Runner final : PoolJob {
    void run(int task, int thread) override;
    BackgroundJob* job = nullptr;  // written by start() only while no job runs
    bool thread_set_up = false;    // the task's thread only
    std::atomic<uint64_t> allocations{0};
    std::atomic<double> milliseconds{0};
  };
  Runner runner_;
  bool running_ = false;
  mutable WorkerPool pool_{1};  // last: its thread stops (after the job in flight) before the runner goes
};

}  // namespace mcslam
