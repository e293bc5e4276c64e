#include "mcslam/core/worker_pool.hpp"

#include <algorithm>
#include <string>

#include "mcslam/core/error.hpp"

namespace mcslam {

WorkerPool::WorkerPool(int threads) {
  if (threads < 0) throw InputError("WorkerPool: threads = " + std::to_string(threads) + ", at least 0");
  workers_.reserve(static_cast<std::size_t>(threads));
  for (int i = 0; i < threads; ++i) workers_.emplace_back([this, i] { workerLoop(i); });
}

WorkerPool::~WorkerPool() {
  wait();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

int WorkerPool::hardwareThreads() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

void WorkerPool::submit(PoolJob& job, int tasks) {
  wait();
  if (tasks <= 0) return;
  if (workers_.empty()) {
    for (int t = 0; t < tasks; ++t) job.run(t, 0);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = &job;
    tasks_ = tasks;
    next_.store(0, std::memory_order_relaxed);
    active_ = threads();
    ++generation_;
  }
  wake_.notify_all();
}

void WorkerPool::wait() {
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [this] { return active_ == 0; });
  job_ = nullptr;
}

bool WorkerPool::idle() {
  std::lock_guard<std::mutex> lock(mutex_);
  return active_ == 0;
}

void WorkerPool::run(PoolJob& job, int tasks) {
  submit(job, tasks);
  if (tasks <= 0 || workers_.empty()) return;
  try {
    drain(threads());
  } catch (...) {
    wait();  // the workers still read the job: let them finish before the caller's stack unwinds
    throw;
  }
  wait();
}

// The hand-out is one counter: its modification order is the order in which tasks are taken.
void WorkerPool::drain(int thread) {
  for (int t = next_.fetch_add(1, std::memory_order_relaxed); t < tasks_;
       t = next_.fetch_add(1, std::memory_order_relaxed)) {
    job_->run(t, thread);
  }
}

void WorkerPool::workerLoop(int thread) {
  uint64_t seen = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stopping_ || generation_ != seen; });
    if (generation_ == seen) return;  // stopping, and no batch left (the destructor waited for the last one)
    seen = generation_;
    lock.unlock();
    drain(thread);
    lock.lock();
    if (--active_ == 0) done_.notify_all();
  }
}

}  // namespace mcslam
