// WorkerPool: each task once on a valid thread, hand-out in index order, visibility across submit/wait and
// between batches, no allocation per batch after warm-up, and a clean shutdown with work pending.
// A broken ordering or participation guarantee shows as a hang (the test's timeout), never as a timing assertion.
#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "alloc_testing.hpp"
#include "mcslam/core/alloc_counter.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/core/worker_pool.hpp"

namespace mcslam {
namespace {

// Counts the runs of each task and records whether every thread index was in range.
class CountingJob final : public PoolJob {
 public:
  CountingJob(int tasks, int max_thread) : runs_(static_cast<std::size_t>(tasks)), max_thread_(max_thread) {}
  void run(int task, int thread) override {
    runs_[static_cast<std::size_t>(task)].fetch_add(1);
    if (thread < 0 || thread > max_thread_) bad_thread_.store(true);
  }
  bool eachRanOnce() const {
    for (const std::atomic<int>& r : runs_) {
      if (r.load() != 1) return false;
    }
    return true;
  }
  void reset() {
    for (std::atomic<int>& r : runs_) r.store(0);
  }
  bool badThread() const { return bad_thread_.load(); }

 private:
  std::vector<std::atomic<int>> runs_;
  int max_thread_;
  std::atomic<bool> bad_thread_{false};
};

TEST(WorkerPool, EveryTaskRunsOnceOnAThreadOfItsRange) {
  for (int threads : {0, 1, 2, 4}) {
    WorkerPool pool(threads);
    EXPECT_EQ(pool.threads(), threads);
    for (int tasks : {0, 1, 7, 1000}) {
      CountingJob submitted(tasks, std::max(0, threads - 1));  // workers only
      pool.submit(submitted, tasks);
      pool.wait();
      EXPECT_TRUE(submitted.eachRanOnce()) << threads << " threads, " << tasks << " tasks";
      EXPECT_FALSE(submitted.badThread());
      CountingJob helped(tasks, threads);  // the caller is thread `threads`
      pool.run(helped, tasks);
      EXPECT_TRUE(helped.eachRanOnce()) << threads << " threads, " << tasks << " tasks";
      EXPECT_FALSE(helped.badThread());
    }
  }
}

TEST(WorkerPool, NegativeThreadCountIsRefused) { EXPECT_THROW(WorkerPool(-1), InputError); }

TEST(WorkerPool, WithoutWorkersTheCallerRunsTheBatch) {
  WorkerPool pool(0);
  const std::thread::id caller = std::this_thread::get_id();
  std::vector<int> order;
  order.reserve(5);
  bool elsewhere = false;
  pool.forEach(5, [&](int task, int thread) {
    order.push_back(task);
    elsewhere = elsewhere || std::this_thread::get_id() != caller || thread != 0;
  });
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_FALSE(elsewhere);
}

TEST(WorkerPool, OneWorkerTakesTheTasksInIndexOrder) {
  WorkerPool pool(1);
  std::vector<int> order;
  order.reserve(100);
  struct Recorder final : PoolJob {
    std::vector<int>* order;
    void run(int task, int) override { order->push_back(task); }
  } job;
  job.order = &order;
  pool.submit(job, 100);  // the single worker alone
  pool.wait();
  ASSERT_EQ(order.size(), 100u);
  for (int t = 0; t < 100; ++t) EXPECT_EQ(order[static_cast<std::size_t>(t)], t);
}

// idle() answers without blocking: false while a batch runs (its task holds until released), true once done.
TEST(WorkerPool, IdleTellsWhetherABatchRuns) {
  WorkerPool pool(1);
  EXPECT_TRUE(pool.idle());
  struct Held final : PoolJob {
    std::atomic<bool> started{false}, release{false};
    void run(int, int) override {
      started = true;
      while (!release) std::this_thread::yield();
    }
  } job;
  pool.submit(job, 1);
  while (!job.started) std::this_thread::yield();
  EXPECT_FALSE(pool.idle());
  job.release = true;
  pool.wait();
  EXPECT_TRUE(pool.idle());
}

// Every task waits until the task before it has started: possible only if no task is taken before the earlier
// ones (FeatureWorkers' follow-up tasks rely on it).
TEST(WorkerPool, ATaskMayWaitForAnEarlierTaskOfItsBatch) {
  constexpr int kTasks = 300;
  WorkerPool pool(3);
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<uint8_t> started(kTasks, 0);
  for (int round = 0; round < 5; ++round) {
    std::fill(started.begin(), started.end(), 0);
    pool.forEach(kTasks, [&](int task) {
      std::unique_lock<std::mutex> lock(mutex);
      started[static_cast<std::size_t>(task)] = 1;
      cv.notify_all();
      cv.wait(lock, [&] { return task == 0 || started[static_cast<std::size_t>(task - 1)] != 0; });
    });
    for (int t = 0; t < kTasks; ++t) ASSERT_EQ(started[static_cast<std::size_t>(t)], 1);
  }
}

// run() makes the caller a thread of the batch: two tasks that wait for each other finish with one worker.
TEST(WorkerPool, RunLetsTheCallerTakeTasks) {
  WorkerPool pool(1);
  std::mutex mutex;
  std::condition_variable cv;
  int arrived = 0;
  pool.forEach(2, [&](int) {
    std::unique_lock<std::mutex> lock(mutex);
    ++arrived;
    cv.notify_all();
    cv.wait(lock, [&] { return arrived == 2; });
  });
  EXPECT_EQ(arrived, 2);
}

// submit() returns while the batch runs: the tasks wait for a release that the caller gives after submit().
TEST(WorkerPool, SubmitReturnsBeforeTheBatchFinishes) {
  WorkerPool pool(2);
  std::atomic<bool> released{false};
  std::atomic<int> done{0};
  struct Blocked final : PoolJob {
    std::atomic<bool>* released;
    std::atomic<int>* done;
    void run(int, int) override {
      while (!released->load()) std::this_thread::yield();
      done->fetch_add(1);
    }
  } job;
  job.released = &released;
  job.done = &done;
  pool.submit(job, 4);
  released.store(true);
  pool.wait();
  EXPECT_EQ(done.load(), 4);
}

// Plain (non-atomic) data: the caller's writes before a batch reach its tasks, the tasks' writes reach the
// caller after wait(), and each batch sees the one before.
TEST(WorkerPool, WritesAreVisibleAcrossSubmitWaitAndBatches) {
  constexpr int kTasks = 257;
  WorkerPool pool(2);
  std::vector<int64_t> value(kTasks);
  for (int t = 0; t < kTasks; ++t) value[static_cast<std::size_t>(t)] = t;
  struct Step final : PoolJob {
    std::vector<int64_t>* value;
    int64_t add = 0;
    void run(int task, int) override {
      (*value)[static_cast<std::size_t>(task)] = 3 * (*value)[static_cast<std::size_t>(task)] + add;
    }
  } job;
  job.value = &value;
  std::vector<int64_t> expected = value;
  for (int round = 0; round < 20; ++round) {
    job.add = round;  // written by the caller between batches
    if (round % 2 == 0) {
      pool.submit(job, kTasks);
      pool.wait();
    } else {
      pool.run(job, kTasks);
    }
    for (int64_t& e : expected) e = 3 * e + round;
    ASSERT_EQ(value, expected) << "round " << round;
    for (int64_t& v : value) v %= 1000003;  // the caller's own writes, read by the next batch
    for (int64_t& e : expected) e %= 1000003;
  }
}

TEST(WorkerPool, BatchesAllocateNothingAfterWarmUp) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  WorkerPool pool(2);
  CountingJob job(64, 2);
  std::atomic<int> sum{0};
  auto add = [&](int task) { sum.fetch_add(task); };
  pool.submit(job, 64);  // warm-up
  pool.wait();
  pool.forEach(64, add);
  const uint64_t before = alloc::totalCount();  // all threads of the process
  for (int round = 0; round < 50; ++round) {
    job.reset();
    pool.submit(job, 64);
    pool.wait();
    job.reset();
    pool.run(job, 64);
    pool.forEach(64, add);
  }
  EXPECT_EQ(alloc::totalCount() - before, 0u);
  EXPECT_TRUE(job.eachRanOnce());
  EXPECT_EQ(sum.load(), 51 * (63 * 64 / 2));
}

// Destroyed right after submit(), without wait(): every task of the batch still runs once before the threads
// stop. And destroyed idle, right after construction.
TEST(WorkerPool, ShutdownFinishesTheBatchInFlight) {
  for (int round = 0; round < 20; ++round) {
    CountingJob job(500, 1);
    {
      WorkerPool pool(1 + round % 2);
      pool.submit(job, 500);
    }
    EXPECT_TRUE(job.eachRanOnce()) << "round " << round;
    EXPECT_FALSE(job.badThread());
    WorkerPool idle(1 + round % 3);
  }
}

}  // namespace
}  // namespace mcslam
