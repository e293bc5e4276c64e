#pragma once
// The sliding-window solve on a thread of its own (the paper's local mapping runs beside tracking): the
// tracking thread hands over a prepared window and goes on with the next frame; it collects the result at a
// fixed point (before it touches the map again), so the output does not depend on thread timing.
#include <cstdint>

#include "mcslam/backend/sliding_window_solver.hpp"
#include "mcslam/core/worker_pool.hpp"

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
  uint64_t allocations() const { return solve_.allocations; }  // by this thread, all solves (after wait())

 private:
  // One solve as a batch of one task on the pool's single thread; its fields are written by start() and by
  // the task, never both at once (start() waits for the previous solve first).
  struct SolveJob final : PoolJob {
    void run(int task, int thread) override;
    backend::SlidingWindowSolver* solver = nullptr;
    int iterations = 0;
    backend::SolveSummary summary;
    uint64_t allocations = 0;
  };
  SolveJob solve_;
  mutable WorkerPool pool_{1};  // last: its thread stops before the job goes
};

}  // namespace mcslam
