#include "mcslam/core/background_task.hpp"

#include <chrono>

#include "mcslam/core/alloc_counter.hpp"

namespace mcslam {
namespace {
std::atomic<BackgroundThreadSetup> thread_setup{nullptr};
}  // namespace

void setBackgroundThreadSetup(BackgroundThreadSetup setup) { thread_setup.store(setup); }

void BackgroundTask::start(BackgroundJob& job) {
  pool_.wait();
  runner_.job = &job;
  running_ = true;
  pool_.submit(runner_, 1);
}

bool BackgroundTask::collect() {
  if (!running_) return false;
  pool_.wait();
  running_ = false;
  return true;
}

void BackgroundTask::Runner::run(int /*task*/, int /*thread*/) {
  const uint64_t allocations_before = alloc::threadCount();  // the setup's count too: it may run after warm-up
  if (!thread_set_up) {
    thread_set_up = true;
    if (const BackgroundThreadSetup setup = thread_setup.load()) setup();
  }
  const auto start = std::chrono::steady_clock::now();
  job->run();
  milliseconds.store(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count(),
                     std::memory_order_relaxed);
  allocations.fetch_add(alloc::threadCount() - allocations_before, std::memory_order_relaxed);
}

}  // namespace mcslam
