// The front-end spreads the multi-view matcher's cameras and pairs over its ORB workers: its features must be
// exactly those of the sequential path (each camera extracted alone, then MultiViewMatcher::compute()), for
// any thread count, with a camera absent too, and with the subpixel alignment of the partners on (its tasks also
// triangulate the tracks they aligned, in any order).
#include <gtest/gtest.h>

#include <cstring>
#include <utility>

#include "mcslam/pipeline/front_end.hpp"
#include "mcslam/pipeline/pipeline_config.hpp"
#include "sim_frames.hpp"

using namespace mcslam;

namespace {

void expectSameFeatures(const FrameFeatures& a, const FrameFeatures& b) {
  ASSERT_EQ(a.cameras(), b.cameras());
  for (int c = 0; c < a.cameras(); ++c) {
    ASSERT_EQ(a.present[c], b.present[c]) << "camera " << c;
    ASSERT_EQ(a.sets[c].count, b.sets[c].count) << "camera " << c;
    for (int k = 0; k < a.sets[c].count; ++k) {
      ASSERT_EQ(a.sets[c].keypoints[k].x, b.sets[c].keypoints[k].x);
      ASSERT_EQ(a.sets[c].keypoints[k].y, b.sets[c].keypoints[k].y);
      ASSERT_EQ(a.bearings[c][k], b.bearings[c][k]);
      ASSERT_EQ(a.mv_of[c][k], b.mv_of[c][k]) << "camera " << c << " keypoint " << k;
    }
  }
  ASSERT_EQ(a.mv_count, b.mv_count);
  ASSERT_EQ(a.mv_ref_count, b.mv_ref_count);
  for (int t = 0; t < a.mv_count; ++t) {
    ASSERT_EQ(a.mv[t].first, b.mv[t].first);
    ASSERT_EQ(a.mv[t].size, b.mv[t].size);
    ASSERT_EQ(a.mv[t].metric, b.mv[t].metric);
    ASSERT_EQ(a.mv[t].p_b, b.mv[t].p_b) << "track " << t;
    ASSERT_EQ(a.mv[t].descriptor, b.mv[t].descriptor);
  }
  for (int r = 0; r < a.mv_ref_count; ++r) {
    ASSERT_EQ(a.mv_refs[r].cam, b.mv_refs[r].cam);
    ASSERT_EQ(a.mv_refs[r].index, b.mv_refs[r].index);
  }
}

TEST(FrontEnd, MatchingOnTheWorkersGivesTheSequentialFeatures) {
  sim::Simulation& sim = test::sharedSimulation("isec", "indoor");
  const std::vector<int> front = {0, 1, 2, 3, 4};
  const Rig rig = sim.rig().subset(front);
  const test::RenderedFrame rendered = test::renderFrame(sim, sim.frameCount() / 3, front);

  for (const auto& [camera_absent, align] :
       {std::pair{false, false}, std::pair{true, false}, std::pair{false, true}, std::pair{true, true}}) {
    RigFrameView view = rendered.view();
    view.cameras = rig.size();
    std::unique_ptr<bool[]> present(new bool[rig.size()]);
    for (int c = 0; c < rig.size(); ++c) present[c] = !(camera_absent && c == 2);  // the middle camera
    view.present = present.get();

    PipelineConfig config = parsePipelineConfig(YAML::Node(), "defaults", rig);
    // The subpixel alignment runs on the workers too, in tasks of consecutive tracks.
    config.multiview.align_subpixel = align;
    // The sequential reference: one extractor per camera, then the matcher on one thread.
    FrameFeatures expected(rig.size(), config.orb.max_features);
    OverlapMap overlap(rig, config.overlap);
    MultiViewMatcher matcher(rig, overlap, config.multiview, config.orb.max_features);
    for (int c = 0; c < rig.size(); ++c) {
      expected.present[c] = present[c] ? 1 : 0;
      expected.sets[c].clear();
      if (!present[c]) continue;
      OrbExtractor extractor(config.orb, rig.model(c).width(), rig.model(c).height());
      ASSERT_EQ(extractor.extract(view.images[c], expected.sets[c]), OrbStatus::kOk);
    }
    matcher.compute(expected, view.images);
    ASSERT_GT(expected.mv_count, 200);
    if (align) {
      ASSERT_GT(matcher.stats().aligned, 500);
    }

    for (const int threads : {1, 2, 3}) {
      config.feature_threads = threads;
      FrontEnd front_end(rig, config);
      FrameFeatures f(rig.size(), front_end.capacityPerCamera());
      for (int repeat = 0; repeat < 3; ++repeat) {  // reused storage, other interleavings
        front_end.compute(view, f);
        SCOPED_TRACE(testing::Message() << "threads " << threads << ", camera absent " << camera_absent << ", aligned "
                                        << align);
        expectSameFeatures(expected, f);
        EXPECT_EQ(front_end.multiViewStats().aligned, matcher.stats().aligned);
        EXPECT_EQ(front_end.multiViewStats().disagreeing, matcher.stats().disagreeing);
      }
    }
  }
}

// The alignment's tasks triangulate and judge the tracks they aligned (TrackBuilder::solveTrack) for the
// emission: in reverse order they must give compute()'s features and counts (nothing carried from task to task).
TEST(FrontEnd, AlignmentTasksInReverseOrderGiveTheSameTracks) {
  sim::Simulation& sim = test::sharedSimulation("isec", "indoor");
  const std::vector<int> front = {0, 1, 2, 3, 4};
  const Rig rig = sim.rig().subset(front);
  const test::RenderedFrame rendered = test::renderFrame(sim, sim.frameCount() / 3, front);
  PipelineConfig config = parsePipelineConfig(YAML::Node(), "defaults", rig);
  config.multiview.align_subpixel = true;
  const OverlapMap overlap(rig, config.overlap);
  FrameFeatures expected(rig.size(), config.orb.max_features);
  for (int c = 0; c < rig.size(); ++c) {
    expected.present[c] = 1;
    OrbExtractor extractor(config.orb, rig.model(c).width(), rig.model(c).height());
    ASSERT_EQ(extractor.extract(rendered.view().images[c], expected.sets[c]), OrbStatus::kOk);
  }
  FrameFeatures f = expected;
  MultiViewMatcher reference(rig, overlap, config.multiview, config.orb.max_features);
  reference.compute(expected, rendered.view().images);

  MultiViewMatcher matcher(rig, overlap, config.multiview, config.orb.max_features);
  matcher.beginFrame(f, rendered.view().images);
  for (int c = 0; c < rig.size(); ++c) matcher.prepareCamera(f, c);
  for (int p = 0; p < matcher.pairCount(); ++p) matcher.matchPair(f, p, 0);
  matcher.mergeFrame(f);
  ASSERT_GT(matcher.alignTaskCount(), 2);
  for (int task = matcher.alignTaskCount() - 1; task >= 0; --task) matcher.alignTracks(f, task);
  matcher.emitTracks(f);
  expectSameFeatures(expected, f);
  EXPECT_GT(reference.stats().dropped, 0);
  EXPECT_EQ(matcher.stats().dropped, reference.stats().dropped);
  EXPECT_EQ(matcher.stats().tracks_with_point, reference.stats().tracks_with_point);
  EXPECT_EQ(matcher.stats().metric_tracks, reference.stats().metric_tracks);
  EXPECT_EQ(matcher.stats().aligned, reference.stats().aligned);
}

}  // namespace
