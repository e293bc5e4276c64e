#pragma once
// The loop closer's pose-graph solve on a thread of its own, so that correcting a map of thousands of keyframes
// never holds up a frame: the frame thread hands over a graph it built and goes on; it takes the solution at a
// frame boundary, either the first at which it is ready (a live rig) or the next one, waiting for it (runs that
// must repeat exactly).
#include <cstdint>

#include "mcslam/backend/pose_graph.hpp"
#include "mcslam/core/worker_pool.hpp"

namespace mcslam {

class PoseGraphWorker {
 public:
  PoseGraphWorker() = default;  // starts the thread (the only allocation)
  PoseGraphWorker(const PoseGraphWorker&) = delete;
  PoseGraphWorker& operator=(const PoseGraphWorker&) = delete;

  // Starts optimizing `graph`, which nobody else may touch until the solve is collected.
  void start(backend::PoseGraph& graph);
  bool running() const { return running_; }
  // True when the solve started last has finished (at once, without blocking).
  bool ready() { return !running_ || pool_.idle(); }
  // Blocks until the solve has finished; false when none was started since the last collect().
  bool collect();
  double lastSolveMs() const { return solve_.milliseconds; }
  uint64_t allocations() {  // by this thread, all solves so far
    pool_.wait();
    return solve_.allocations;
  }

 private:
  // One solve as a batch of one task on the pool's single thread: its fields are written by start() and by the
  // task, never both at once (start() and collect() wait for the task first).
  struct SolveJob final : PoolJob {
    void run(int task, int thread) override;
    backend::PoseGraph* graph = nullptr;
    double milliseconds = 0;
    uint64_t allocations = 0;
  };
  SolveJob solve_;
  bool running_ = false;
  WorkerPool pool_{1};  // last: its thread stops before the job goes
};

}  // namespace mcslam
