#include "pose_graph_worker.hpp"

#include <chrono>

#include "mcslam/core/alloc_counter.hpp"

namespace mcslam {

void PoseGraphWorker::start(backend::PoseGraph& graph) {
  pool_.wait();
  solve_.graph = &graph;
  running_ = true;
  pool_.submit(solve_, 1);
}

bool PoseGraphWorker::collect() {
  if (!running_) return false;
  pool_.wait();
  running_ = false;
  return true;
}

void PoseGraphWorker::SolveJob::run(int /*task*/, int /*thread*/) {
  const uint64_t allocations_before = alloc::threadCount();
  const auto start = std::chrono::steady_clock::now();
  graph->optimize();
  milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  allocations += alloc::threadCount() - allocations_before;
}

}  // namespace mcslam
