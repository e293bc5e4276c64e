#include "backend_worker.hpp"

#include "mcslam/core/alloc_counter.hpp"

namespace mcslam {

BackendWorker::BackendWorker() : thread_([this] { run(); }) {}

BackendWorker::~BackendWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void BackendWorker::start(backend::SlidingWindowSolver& solver, int iterations) {
  wait();  // one solve at a time
  {
    std::lock_guard<std::mutex> lock(mutex_);
    solver_ = &solver;
    iterations_ = iterations;
    pending_ = true;
  }
  cv_.notify_all();
}

backend::SolveSummary BackendWorker::wait() const {
  std::unique_lock<std::mutex> lock(mutex_);
  cv_.wait(lock, [this] { return !pending_; });
  return summary_;
}

void BackendWorker::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    cv_.wait(lock, [this] { return pending_ || stop_; });
    if (stop_) return;
    backend::SlidingWindowSolver& solver = *solver_;
    const int iterations = iterations_;
    lock.unlock();
    const uint64_t allocations_before = alloc::threadCount();
    const backend::SolveSummary summary = solver.solve(iterations);
    const uint64_t allocated = alloc::threadCount() - allocations_before;
    lock.lock();
    summary_ = summary;
    allocations_ += allocated;
    pending_ = false;
    cv_.notify_all();
  }
}

}  // namespace mcslam
