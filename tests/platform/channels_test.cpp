// The channels between the daemon's threads besides the plain rings: SignalledRing (a drop-oldest ring whose
// consumer sleeps until an item comes or it is told to stop), BackPressure (a lossless replay waits for the
// pipeline) and WarmUp.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "realtime/signalled_ring.hpp"
#include "realtime/warm_up.hpp"
#include "sources/back_pressure.hpp"

using namespace mcslam::platform;

TEST(SignalledRing, TheConsumerGetsItemsInOrderAndNullOnceStoppedAndEmpty) {
  SignalledRing<int> ring(4);
  std::atomic<bool> stop{false};
  for (int i = 1; i <= 3; ++i) {
    ring.slot() = i;
    EXPECT_FALSE(ring.publish());
  }
  stop = true;  // stopping still hands out what is queued
  for (int want = 1; want <= 3; ++want) {
    int* item = ring.next(stop);
    ASSERT_NE(item, nullptr);
    EXPECT_EQ(*item, want);
    ring.release();
  }
  EXPECT_EQ(ring.next(stop), nullptr);
}

TEST(SignalledRing, AFullRingDropsTheOldestAndCountsIt) {
  SignalledRing<int> ring(2);
  std::atomic<bool> stop{true};
  for (int i = 1; i <= 5; ++i) {
    ring.slot() = i;
    EXPECT_EQ(ring.publish(), i > 2) << i;
  }
  EXPECT_EQ(ring.dropped(), 3u);
  EXPECT_EQ(*ring.next(stop), 4);
  ring.release();
  EXPECT_EQ(*ring.next(stop), 5);
  ring.release();
}

TEST(SignalledRing, AWaitingConsumerWakesForAnItemAndForAStop) {
  SignalledRing<int> ring(2);
  std::atomic<bool> stop{false};
  int got = 0;
  bool ended = false;
  std::thread consumer([&] {
    while (int* item = ring.next(stop)) {
      got += *item;
      ring.release();
    }
    ended = true;
  });
  ring.slot() = 7;
  ring.publish();
  while (ring.size() != 0) std::this_thread::yield();  // taken (liveness only)
  stop = true;
  ring.wake();
  consumer.join();
  EXPECT_EQ(got, 7);
  EXPECT_TRUE(ended);
}

TEST(BackPressure, ASourceMayRunTwoFramesAheadOfWhatIsDone) {
  BackPressure pressure;
  std::atomic<bool> stop{false};
  EXPECT_TRUE(pressure.waitForRoom(0, stop));
  EXPECT_TRUE(pressure.waitForRoom(1, stop));
  // Two emitted, none done: the third waits until one is done.
  std::atomic<bool> room{false};
  std::thread source([&] { room = pressure.waitForRoom(2, stop, 60000000000); });
  pressure.done();
  source.join();
  EXPECT_TRUE(room.load());
  EXPECT_EQ(pressure.doneCount(), 1u);
}

TEST(BackPressure, AStopEndsTheWaitWithFalse) {
  BackPressure pressure;
  std::atomic<bool> stop{false};
  std::atomic<bool> result{true};
  std::thread source([&] { result = pressure.waitForRoom(5, stop, 60000000000); });
  stop = true;
  source.join();
  EXPECT_FALSE(result.load());
}

TEST(BackPressure, AVanishedFrameDoesNotBlockTheSourceForever) {
  BackPressure pressure;
  std::atomic<bool> stop{false};
  EXPECT_TRUE(pressure.waitForRoom(5, stop, 1000000));  // gives up after 1 ms without progress
}

TEST(WarmUp, EndsAndRemembersAfterHowManyFrames) {
  WarmUp warm_up;
  EXPECT_FALSE(warm_up.warm());
  warm_up.end(50);
  EXPECT_TRUE(warm_up.warm());
  EXPECT_EQ(warm_up.countAtEnd(), 50u);
}
