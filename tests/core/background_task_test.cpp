// BackgroundTask's thread setup: the hook the platform layer registers runs on the task's own thread, once per
// thread, before the first job, and never on the thread that hands the jobs over.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "mcslam/core/background_task.hpp"

namespace mcslam {
namespace {

std::atomic<int> setups{0};
std::atomic<std::thread::id> setup_thread{};

void recordSetup() {
  setups.fetch_add(1);
  setup_thread.store(std::this_thread::get_id());
}

// Sets the process-wide hook for one test and clears it however the test ends.
class SetupHook {
 public:
  explicit SetupHook(BackgroundThreadSetup setup) { setBackgroundThreadSetup(setup); }
  ~SetupHook() { setBackgroundThreadSetup(nullptr); }
  SetupHook(const SetupHook&) = delete;
  SetupHook& operator=(const SetupHook&) = delete;
};

class RecordThread final : public BackgroundJob {
 public:
  void run() override {
    thread = std::this_thread::get_id();
    setups_seen = setups.load();
  }
  std::thread::id thread{};
  int setups_seen = -1;
};

TEST(BackgroundTask, TheThreadSetupRunsOnceOnEachTasksThreadBeforeItsFirstJob) {
  setups.store(0);
  const SetupHook hook(&recordSetup);
  RecordThread job;
  BackgroundTask first, second;
  for (int round = 0; round < 3; ++round) {
    first.start(job);
    ASSERT_TRUE(first.collect());
    EXPECT_EQ(job.setups_seen, 1) << "round " << round;  // before the first job, and not again
  }
  EXPECT_EQ(setup_thread.load(), job.thread);
  EXPECT_NE(job.thread, std::this_thread::get_id());

  second.start(job);  // another task: its own thread, set up too
  ASSERT_TRUE(second.collect());
  EXPECT_EQ(setups.load(), 2);
  EXPECT_EQ(setup_thread.load(), job.thread);
}

TEST(BackgroundTask, WithoutASetupJobsRunAsBefore) {
  setups.store(0);
  const SetupHook hook(nullptr);
  RecordThread job;
  BackgroundTask task;
  task.start(job);
  ASSERT_TRUE(task.collect());
  EXPECT_EQ(job.setups_seen, 0);
  EXPECT_NE(job.thread, std::thread::id{});
}

}  // namespace
}  // namespace mcslam
