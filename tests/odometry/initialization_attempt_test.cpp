#include <gtest/gtest.h>

#include <thread>

#include "alloc_testing.hpp"
#include "mcslam/features/multiview_matcher.hpp"
#include "mcslam/odometry/initialization_attempt.hpp"
#include "synthetic_sequence.hpp"

using namespace mcslam;

// An attempt on its own thread works on its copy of the frame, and gives what the same attempt gives on the
// caller's thread: the caller may refill its frame buffer (the next frame's features) while it runs.
TEST(InitializationAttempt, RunsOnItsOwnThreadOnACopyWithTheResultOfTheCallersThread) {
  test::SyntheticSequenceOptions so;
  so.frames = 30;
  const Rig rig = test::isecRig().subset({2});
  test::SyntheticSequence seq(rig, so);
  OverlapMap overlap(rig, OverlapOptions{});
  MultiViewMatcher matcher(rig, overlap, MultiViewOptions{}, so.max_features);
  FrameFeatures f(rig.size(), so.max_features);
  const OdometryOptions oo;
  Initializer for_thread(rig, oo, so.max_features), for_caller(rig, oo, so.max_features);
  InitializationAttempt threaded(for_thread, rig.size(), so.max_features, /*on_thread=*/true);
  InitializationAttempt in_line(for_caller, rig.size(), so.max_features, /*on_thread=*/false);

  int ready = 0;
  uint64_t thread_allocations_after_first = 0;  // the thread's first job may set it up
  for (int i = 0; i < so.frames; ++i) {
    seq.fill(i, f);
    matcher.compute(f);
    threaded.submit(f, static_cast<uint64_t>(i));
    in_line.submit(f, static_cast<uint64_t>(i));
    EXPECT_TRUE(threaded.pending());
    seq.fill(0, f);  // the caller's buffer changes under the attempt
    matcher.compute(f);
    SE3 T_threaded, T_in_line;
    const Initializer::TwoFrame r_threaded = threaded.collect(T_threaded);
    const Initializer::TwoFrame r_in_line = in_line.collect(T_in_line);
    EXPECT_FALSE(threaded.pending());
    if (i == 0) thread_allocations_after_first = threaded.threadAllocations();
    EXPECT_NE(threaded.lastThread(), std::this_thread::get_id());
    EXPECT_EQ(in_line.lastThread(), std::this_thread::get_id());
    ASSERT_EQ(r_threaded, r_in_line) << "frame " << i;
    if (r_threaded != Initializer::TwoFrame::Ready) continue;
    ++ready;
    EXPECT_EQ(T_threaded.t, T_in_line.t) << "frame " << i;
    EXPECT_EQ(T_threaded.R, T_in_line.R) << "frame " << i;
    EXPECT_EQ(threaded.frameIndex(), static_cast<uint64_t>(i));
  }
  EXPECT_GE(ready, 5);  // the attempts succeed once the rig has moved, and go on succeeding on this reference
  if (test::countsAllocations()) {
    EXPECT_EQ(threaded.threadAllocations(), thread_allocations_after_first);
  }
}
