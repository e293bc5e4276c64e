#pragma once
// A fixed set of worker threads that run batches of indexed tasks: the one pool of the code base (the front-end's
// ORB workers, the back-end's solver thread and the simulator's renderer use it). The threads start in the
// constructor and stop in the destructor; submitting and waiting allocate nothing, so that work handed to the
// pool after warm-up keeps the fixed-memory rule.
//
// Guarantees:
//  - every task of a batch runs exactly once, on a worker (or, in run(), possibly on the calling thread);
//  - tasks are handed out in increasing index order: once task k is taken, every task below k has been taken by
//    a thread that runs it, so a task may wait for an earlier task of its batch without deadlock;
//  - what the caller wrote before submit() or run() is visible to the tasks, and what the tasks wrote is visible
//    to the caller once wait() or run() returned;
//  - one batch at a time: submit() first waits for the previous batch;
//  - the destructor lets the batch in flight finish (every one of its tasks runs) before the threads stop.
// One thread drives a pool (submit, wait, run); tasks must not throw.
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace mcslam {

// The work of a batch: run(task, thread) for every task, each once. `thread` identifies the thread running the
// task (no two concurrent tasks share one), for per-thread scratch: a worker's index in [0, threads()), or
// threads() for the calling thread.
class PoolJob {
 public:
  virtual void run(int task, int thread) = 0;

 protected:
  ~PoolJob() = default;
};

class WorkerPool {
 public:
  // Starts `threads` worker threads (the pool's only allocations). With none, every batch runs on the caller.
  // Throws mcslam::InputError for threads < 0.
  explicit WorkerPool(int threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()); }
  // std::thread::hardware_concurrency(), at least 1.
  static int hardwareThreads();

  // Starts tasks [0, tasks) of `job` on the workers and returns; `job` must live until wait() returned. Without
  // workers the tasks run here, before submit() returns.
  void submit(PoolJob& job, int tasks);
  // Blocks until the batch submitted last has finished (at once when none runs).
  void wait();
  // True when no batch runs (the last one finished): wait() would return at once. Does not block.
  bool idle();
  // submit() and wait(), with the calling thread taking tasks too (as thread threads()).
  void run(PoolJob& job, int tasks);
  // run() for a callable: fn(task), or fn(task, thread).
  template <class Fn>
  void forEach(int tasks, const Fn& fn);

 private:
  void workerLoop(int thread);
  void drain(int thread);  // takes and runs the current batch's tasks until none is left

  std::mutex mutex_;
  std::condition_variable wake_, done_;
  PoolJob* job_ = nullptr;  // the current batch (written under mutex_ before generation_ moves)
  int tasks_ = 0;
  std::atomic<int> next_{0};          // next task to hand out
  int active_ = 0;                    // workers not done with the current batch (guarded by mutex_)
  uint64_t generation_ = 0;           // one per batch (guarded by mutex_)
  bool stopping_ = false;             // guarded by mutex_
  std::vector<std::thread> workers_;  // last: started once the members above exist
};

template <class Fn>
void WorkerPool::forEach(int tasks, const Fn& fn) {
  struct Adapter final : PoolJob {
    explicit Adapter(const Fn& f) : fn(f) {}
    void run(int task, int thread) override {
      if constexpr (std::is_invocable_v<const Fn&, int, int>) {
        fn(task, thread);
      } else {
        fn(task);
      }
    }
    const Fn& fn;
  };
  Adapter job(fn);
  run(job, tasks);
}

}  // namespace mcslam
