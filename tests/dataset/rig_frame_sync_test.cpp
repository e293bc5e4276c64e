#include <gtest/gtest.h>

#include "mcslam/dataset/rig_frame_sync.hpp"

using namespace mcslam;

namespace {

constexpr Timestamp kMs = 1000000;

std::vector<CameraImage> images(const std::string& cam, std::initializer_list<Timestamp> stamps_ms) {
  std::vector<CameraImage> out;
  for (Timestamp t : stamps_ms) out.push_back({t * kMs, cam + "/" + std::to_string(t)});
  return out;
}

}  // namespace

TEST(RigFrameSync, JitteredStampsWithinToleranceFormOneFrame) {
  const auto frames = assembleRigFrames({images("a", {0, 50, 100}), images("b", {2, 49, 103})}, 5 * kMs);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[1].t, 49 * kMs);  // the earliest stamp of the frame
  EXPECT_EQ(frames[1].image_paths[0], "a/50");
  EXPECT_EQ(frames[1].image_paths[1], "b/49");
  EXPECT_EQ(frames[2].camera_stamps[1], 103 * kMs);
}

TEST(RigFrameSync, AMissingImageLeavesThatCameraOutInsteadOfShiftingThePairs) {
  const auto frames = assembleRigFrames({images("a", {0, 50, 100, 150}), images("b", {0, 100, 150})}, 5 * kMs);
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(frames[1].image_paths[0], "a/50");
  EXPECT_TRUE(frames[1].image_paths[1].empty());
  EXPECT_EQ(frames[1].camera_stamps[1], 0);
  EXPECT_EQ(frames[2].image_paths[1], "b/100");
  EXPECT_EQ(frames[3].image_paths[1], "b/150");
}

TEST(RigFrameSync, TwoStampsOfOneCameraNeverShareAFrame) {
  // b has two images within the tolerance of a's one: the second starts a frame of its own.
  const auto frames = assembleRigFrames({images("a", {10}), images("b", {9, 12})}, 5 * kMs);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].image_paths[1], "b/9");
  EXPECT_EQ(frames[0].image_paths[0], "a/10");
  EXPECT_EQ(frames[1].image_paths[1], "b/12");
  EXPECT_TRUE(frames[1].image_paths[0].empty());
}

TEST(RigFrameSync, StampsBeyondTheToleranceAreSeparateFrames) {
  const auto frames = assembleRigFrames({images("a", {0}), images("b", {6})}, 5 * kMs);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_TRUE(frames[0].image_paths[1].empty());
  EXPECT_TRUE(frames[1].image_paths[0].empty());
}

TEST(RigFrameSync, AutomaticToleranceIsAThirdOfTheFastestMedianPeriodAtMost5ms) {
  EXPECT_EQ(automaticSyncTolerance({images("a", {0, 9, 18, 27}), images("b", {0, 12, 24})}), 3 * kMs);
  EXPECT_EQ(automaticSyncTolerance({images("a", {0, 50, 100})}), 5 * kMs);
  EXPECT_EQ(automaticSyncTolerance({images("a", {0})}), 5 * kMs);
}
