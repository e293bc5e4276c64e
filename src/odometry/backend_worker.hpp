#pragma once
// The sliding-window solve on a thread of its own (the paper's local mapping runs beside tracking): the
// tracking thread hands over a prepared window and goes on with the next frame; it collects the result at a
// fixed point (before it touches the map again), so the output does not depend on thread timing.
#include <condition_variable>
#include <mutex>
#include <thread>

#include "mcslam/backend/sliding_window_solver.hpp"

namespace mcslam {

class BackendWorker {
 public:
  BackendWorker();  // starts the thread (the only allocation)
  ~BackendWorker();
  BackendWorker(const BackendWorker&) = delete;
  BackendWorker& operator=(const BackendWorker&) = delete;

  // Starts solve(iterations) on `solver`, which nobody else may touch until wait() returns.
  void start(backend::SlidingWindowSolver& solver, int iterations);
  // Blocks until the solve started last has finished (at once when none runs) and returns its summary.
  backend::SolveSummary wait() const;
  uint64_t allocations() const { return allocations_; }       // by this thread, all solves (after wait())

 private:
  void run();

  mutable std::mutex mutex_;
  mutable std::condition_variable cv_;
  backend::SlidingWindowSolver* solver_ = nullptr;
  int iterations_ = 0;
  bool pending_ = false;  // a solve was started and has not finished
  bool stop_ = false;
  backend::SolveSummary summary_;
  uint64_t allocations_ = 0;
  std::thread thread_;  // last: starts once the members above exist
};

}  // namespace mcslam
