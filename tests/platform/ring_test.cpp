// The drop-oldest SPSC ring: order, drop-oldest when full, no allocation, and a two-thread stress test
// in which every item that arrives is whole and in order, and arrivals + drops = items sent.
#include <gtest/gtest.h>

#include <thread>

#include "alloc_testing.hpp"
#include "mcslam/core/alloc_counter.hpp"
#include "realtime/drop_oldest_ring.hpp"

using mcslam::platform::DropOldestRing;

namespace {
struct Item {
  uint64_t id = 0;
  uint64_t check = 0;  // ~id: a torn item would break it
  std::vector<uint8_t> payload;
};
}  // namespace

TEST(DropOldestRing, DeliversInOrderAndDropsTheOldestWhenFull) {
  DropOldestRing<Item> ring(3);
  for (uint64_t i = 1; i <= 5; ++i) {
    ring.writeSlot().id = i;
    const bool dropped = ring.publish();
    EXPECT_EQ(dropped, i > 3) << "item " << i;
  }
  EXPECT_EQ(ring.dropped(), 2u);
  EXPECT_EQ(ring.size(), 3u);
  for (uint64_t want = 3; want <= 5; ++want) {
    Item* it = ring.acquire();
    ASSERT_NE(it, nullptr);
    EXPECT_EQ(it->id, want);  // 1 and 2 were dropped: the oldest go first
    ring.release();
  }
  EXPECT_EQ(ring.acquire(), nullptr);
}

TEST(DropOldestRing, HeldSlotIsNeverOverwrittenWhileTheProducerLaps) {
  DropOldestRing<Item> ring(2);
  ring.writeSlot().id = 1;
  ring.publish();
  Item* held = ring.acquire();
  ASSERT_NE(held, nullptr);
  for (uint64_t i = 2; i < 50; ++i) {
    ring.writeSlot().id = i;
    ring.publish();
  }
  EXPECT_EQ(held->id, 1u);
  ring.release();
  EXPECT_EQ(ring.acquire()->id, 48u);
}

TEST(DropOldestRing, PublishAndAcquireDoNotAllocate) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  DropOldestRing<Item> ring(4, [](Item& it) { it.payload.resize(1024); });
  mcslam::alloc::ThreadScope scope;
  for (uint64_t i = 0; i < 10000; ++i) {
    ring.writeSlot().id = i;
    ring.publish();
    if (i % 3 == 0) {
      if (ring.acquire()) ring.release();
    }
  }
  EXPECT_EQ(scope.count(), 0u);
}

TEST(DropOldestRing, ConcurrentProducerAndConsumerLoseNothingUncounted) {
  constexpr uint64_t kItems = 200000;
  DropOldestRing<Item> ring(4, [](Item& it) { it.payload.assign(64, 0); });
  std::atomic<bool> done{false};
  uint64_t received = 0, last = 0, torn = 0, out_of_order = 0;
  std::thread consumer([&] {
    for (;;) {
      Item* it = ring.acquire();
      if (!it) {
        if (done.load(std::memory_order_acquire) && ring.size() == 0) break;
        std::this_thread::yield();
        continue;
      }
      if (it->check != ~it->id || it->payload[0] != static_cast<uint8_t>(it->id) ||
          it->payload[63] != static_cast<uint8_t>(it->id))
        ++torn;
      if (it->id <= last) ++out_of_order;
      last = it->id;
      ++received;
      ring.release();
    }
  });
  for (uint64_t i = 1; i <= kItems; ++i) {
    Item& it = ring.writeSlot();
    it.id = i;
    it.check = ~i;
    it.payload[0] = it.payload[63] = static_cast<uint8_t>(i);
    ring.publish();
  }
  done.store(true, std::memory_order_release);
  consumer.join();
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(out_of_order, 0u);
  EXPECT_EQ(received + ring.dropped(), kItems);
  EXPECT_EQ(last, kItems);  // the newest item is never the one dropped
}
