// Rig assembly: complete frames leave in order, partial frames after the timeout, late and duplicate
// images are counted, timestamp matching respects the tolerance, and nothing is allocated.
#include <gtest/gtest.h>

#include "daemon/rig_assembler.hpp"
#include "mcslam/core/alloc_counter.hpp"

using namespace mcslam;
using namespace mcslam::platform;

namespace {
constexpr int64_t kMs = 1000000;
const std::vector<std::pair<int, int>> kSizes = {{8, 4}, {8, 4}, {6, 2}};

CameraFrame frameOf(int cam, uint64_t index, Timestamp t) {
  CameraFrame f;
  f.image.resize(kSizes[cam].first, kSizes[cam].second);
  f.image.data()[0] = static_cast<uint8_t>(index * 10 + cam);  // identifies where the pixels came from
  f.trigger_index = index;
  f.capture_ns = t;
  return f;
}

RigFrame outFrame() {
  RigFrame r;
  r.allocate(kSizes);
  return r;
}
}  // namespace

TEST(RigAssembler, ByTriggerCountCompleteFramesLeaveInTriggerOrder) {
  RigAssembler a(kSizes, 4, RigAssembler::MatchBy::TriggerCount, 0, 100 * kMs);
  RigFrame out = outFrame();
  // Camera 2 lags by one trigger: frames 1 and 2 are both pending for a while.
  for (int cam : {0, 1}) {
    auto f = frameOf(cam, 1, 1000);
    ASSERT_TRUE(a.add(cam, f, 0));
  }
  for (int cam : {0, 1}) {
    auto f = frameOf(cam, 2, 2000);
    ASSERT_TRUE(a.add(cam, f, 0));
  }
  EXPECT_FALSE(a.next(out, 1 * kMs));  // frame 1 still misses camera 2
  auto late1 = frameOf(2, 1, 1001);
  a.add(2, late1, 1 * kMs);
  ASSERT_TRUE(a.next(out, 1 * kMs));
  EXPECT_EQ(out.sequence, 1u);
  EXPECT_EQ(out.presentCount(), 3);
  for (int cam = 0; cam < 3; ++cam) EXPECT_EQ(out.images[cam].data()[0], 10 + cam);
  EXPECT_FALSE(a.next(out, 1 * kMs));
  auto f2 = frameOf(2, 2, 2001);
  a.add(2, f2, 2 * kMs);
  ASSERT_TRUE(a.next(out, 2 * kMs));
  EXPECT_EQ(out.sequence, 2u);
  EXPECT_EQ(a.partialFrames(), 0u);
}

TEST(RigAssembler, IncompleteFrameLeavesAfterTheTimeoutWithoutTheMissingCamera) {
  RigAssembler a(kSizes, 4, RigAssembler::MatchBy::TriggerCount, 0, 100 * kMs);
  RigFrame out = outFrame();
  for (int cam : {0, 2}) {
    auto f = frameOf(cam, 5, 5000);
    a.add(cam, f, 0);
  }
  EXPECT_FALSE(a.next(out, 99 * kMs));
  ASSERT_TRUE(a.next(out, 100 * kMs));
  EXPECT_TRUE(out.present[0]);
  EXPECT_FALSE(out.present[1]);
  EXPECT_TRUE(out.present[2]);
  EXPECT_EQ(a.partialFrames(), 1u);
  // Camera 1's image for trigger 5 arriving now is late, not the start of a new frame.
  auto late = frameOf(1, 5, 5000);
  a.add(1, late, 101 * kMs);
  EXPECT_EQ(a.lateImages(), 1u);
  EXPECT_FALSE(a.next(out, 500 * kMs));
}

TEST(RigAssembler, ByTimestampMatchesWithinTheToleranceOnly) {
  RigAssembler a(kSizes, 4, RigAssembler::MatchBy::Timestamp, 2 * kMs, 100 * kMs);
  RigFrame out = outFrame();
  auto f0 = frameOf(0, 0, 1000 * kMs);
  auto f1 = frameOf(1, 0, 1001 * kMs);  // within 2 ms
  auto f2 = frameOf(2, 0, 1004 * kMs);  // 4 ms away: another frame
  a.add(0, f0, 0);
  a.add(1, f1, 0);
  a.add(2, f2, 0);
  ASSERT_TRUE(a.next(out, 100 * kMs));
  EXPECT_EQ(out.capture_ns, 1000 * kMs);
  EXPECT_EQ(out.presentCount(), 2);
  ASSERT_TRUE(a.next(out, 100 * kMs));
  EXPECT_EQ(out.capture_ns, 1004 * kMs);
  EXPECT_EQ(out.presentCount(), 1);
}

TEST(RigAssembler, DuplicatesAreCountedAndAFullTableAsksTheCallerToFlush) {
  RigAssembler a(kSizes, 2, RigAssembler::MatchBy::TriggerCount, 0, 100 * kMs);
  RigFrame out = outFrame();
  auto d1 = frameOf(0, 1, 0), d2 = frameOf(0, 1, 0);
  a.add(0, d1, 0);
  a.add(0, d2, 0);
  EXPECT_EQ(a.duplicateImages(), 1u);
  auto f2 = frameOf(0, 2, 0), f3 = frameOf(0, 3, 0);
  ASSERT_TRUE(a.add(0, f2, 0));
  EXPECT_FALSE(a.add(0, f3, 0));  // two places, both taken
  ASSERT_TRUE(a.next(out, 0, /*force=*/true));
  EXPECT_EQ(out.sequence, 1u);
  EXPECT_TRUE(a.add(0, f3, 0));
}

TEST(RigAssembler, AssemblingAllocatesNothing) {
  RigAssembler a(kSizes, 4, RigAssembler::MatchBy::TriggerCount, 0, 100 * kMs);
  RigFrame out = outFrame();
  std::vector<CameraFrame> frames;
  for (int cam = 0; cam < 3; ++cam) frames.push_back(frameOf(cam, 0, 0));
  alloc::ThreadScope scope;
  for (uint64_t i = 1; i < 3000; ++i) {
    for (int cam = 0; cam < 3; ++cam) {
      frames[cam].trigger_index = i;
      a.add(cam, frames[cam], static_cast<int64_t>(i) * kMs);
    }
    ASSERT_TRUE(a.next(out, static_cast<int64_t>(i) * kMs));
    ASSERT_EQ(out.sequence, i);
  }
  EXPECT_EQ(scope.count(), 0u);
}
