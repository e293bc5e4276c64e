#include "backend_worker.hpp"

#include "mcslam/core/alloc_counter.hpp"

namespace mcslam {

BackendWorker::BackendWorker() = default;

BackendWorker::~BackendWorker() = default;  // the pool lets a solve in flight finish

void BackendWorker::start(backend::SlidingWindowSolver& solver, int iterations) {
  pool_.wait();  // one solve at a time
  solve_.solver = &solver;
  solve_.iterations = iterations;
  pool_.submit(solve_, 1);
}

backend::SolveSummary BackendWorker::wait() const {
  pool_.wait();
  return solve_.summary;
}

void BackendWorker::SolveJob::run(int /*task*/, int /*thread*/) {
  const uint64_t allocations_before = alloc::threadCount();
  summary = solver->solve(iterations);
  allocations += alloc::threadCount() - allocations_before;
}

}  // namespace mcslam
