// Places made while a rig without overlap was finding its unit take their points and pose again when their
// keyframe leaves the odometry's window: the first two keyframes of its start from two frames, which had no
// certain point when they were made, then hold points (a loop back to the start can be measured on them), and
// taking them allocates nothing. Exact synthetic geometry (the odometry's own test sequence), no rendering.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "../odometry/synthetic_sequence.hpp"
#include "alloc_testing.hpp"
#include "mcslam/features/multiview_matcher.hpp"
#include "mcslam/places/loop_scale.hpp"
#include "mcslam/places/place_memory.hpp"
#include "mcslam/recognition/vocabulary.hpp"

namespace mcslam {
namespace {

// Compares each place of an uncertain unit whose odometry keyframe has left the window with that keyframe: it took
// its pose (the odometry keeps it once out of the window). Returns how many it compared.
int expectRefinedPoses(const PlaceMap& places, const Map& local) {
  int compared = 0;
  for (int k = 0; k < local.keyframeCapacity(); ++k) {
    const Keyframe& kf = local.keyframe(k);
    if (!kf.alive || kf.in_backend) continue;
    for (int slot = 0; slot < places.capacity(); ++slot) {
      const PlaceKeyframe& place = places.keyframe(slot);
      if (!place.alive || place.frame_index != kf.frame_index || place.unit_sigma < kUncertainUnit) continue;
      EXPECT_LT((place.T_o_k.t - kf.T_w_b.t).norm(), 1e-9) << "place keyframe " << place.id;
      EXPECT_LT(rotationAngle(place.T_o_k.R, kf.T_w_b.R), 1e-9) << "place keyframe " << place.id;
      ++compared;
    }
  }
  return compared;
}

// The place keyframe with this id, or nullptr.
const PlaceKeyframe* placeOfId(const PlaceMap& map, int64_t id) {
  const int slot = map.slotOfId(id);
  return slot >= 0 ? &map.keyframe(slot) : nullptr;
}

// A rig of three cameras without overlap on the synthetic sequence, its odometry and its place memory (loop
// detections waited for, so that runs repeat); the tests drive the frames themselves.
struct PlacesOnSequence {
  explicit PlacesOnSequence(const test::SyntheticSequenceOptions& so)
      : rig(test::nonOverlappingRig3()),
        seq(rig, so),
        overlap(rig, OverlapOptions{}),
        matcher(rig, overlap, MultiViewOptions{}, so.max_features),
        odometry(rig, odometry_options, so.max_features),
        memory(rig, vocabulary(), repeatable(), odometry_options, so.max_features),
        frame(rig.size(), so.max_features) {}

  static const Vocabulary& vocabulary() {
    static const Vocabulary v = loadVocabulary("");
    return v;
  }
  static PlacesOptions repeatable() {
    PlacesOptions places;
    places.repeatable = true;
    return places;
  }

  Rig rig;
  test::SyntheticSequence seq;
  OverlapMap overlap;
  MultiViewMatcher matcher;
  OdometryOptions odometry_options;
  Odometry odometry;
  PlaceMemory memory;
  FrameFeatures frame;
};

TEST(PlaceRefinement, PlacesOfAnUncertainUnitTakeTheWindowsPointsWhenTheirKeyframeLeavesIt) {
  test::SyntheticSequenceOptions so;
  so.frames = 100;
  so.warmup_frames = 30;  // the refinements come within the first 60 frames
  PlacesOnSequence run(so);
  auto& [rig, seq, overlap, matcher, odometry_options, odometry, memory, frame] = run;
  int first_points_when_made = -1;  // of the map's first place keyframe, in the frame it joined the place map
  uint64_t allocations = 0, refined_in_warm_up = 0;
  int compared = 0;
  for (int i = 0; i < seq.frames(); ++i) {
    seq.fill(i, frame);
    matcher.compute(frame);
    PoseEstimate pose;
    if (i == so.warmup_frames) refined_in_warm_up = memory.stats().places_refined;
    alloc::ThreadScope scope;
    odometry.process(frame, static_cast<uint64_t>(i), pose);
    memory.afterOdometry(frame, static_cast<uint64_t>(i), odometry, pose);
    const uint64_t allocated = scope.count();
    // Before the next solve starts: its window (which keyframes are in it) is the back-end thread's then.
    compared += expectRefinedPoses(memory.map(), odometry.map());
    const alloc::ThreadScope mapping;
    odometry.startDeferredMapping();
    if (i >= so.warmup_frames) allocations += allocated + mapping.count();
    const PlaceKeyframe* first = placeOfId(memory.map(), 0);
    if (first != nullptr && first_points_when_made < 0) first_points_when_made = first->point_count;
  }
  ASSERT_GE(odometry.stats().initializations, 1u);
  EXPECT_EQ(odometry.stats().scale_converged_frame, -1) << "the unit should still be uncertain for this test";
  EXPECT_EQ(first_points_when_made, 0) << "a start from two frames has no certain point yet";
  const PlaceKeyframe* first = placeOfId(memory.map(), 0);
  ASSERT_NE(first, nullptr);
  EXPECT_GT(first->point_count, 50);
  // Each made in an uncertain unit took them, but those still in the window (and the newest, not in it yet).
  int uncertain = 0;
  for (int slot = 0; slot < memory.map().capacity(); ++slot)
    uncertain += memory.map().keyframe(slot).alive && memory.map().keyframe(slot).unit_sigma >= kUncertainUnit;
  std::printf("place keyframes %d, %d of an uncertain unit, %llu refined\n", memory.map().size(), uncertain,
              static_cast<unsigned long long>(memory.stats().places_refined));
  const auto refined = static_cast<int>(memory.stats().places_refined);
  EXPECT_LE(refined, uncertain);
  EXPECT_GE(refined + odometry_options.window_keyframes + 1, uncertain);
  EXPECT_GT(refined, 0);
  EXPECT_GT(compared, 0);
  EXPECT_GT(memory.stats().places_refined, refined_in_warm_up) << "the allocation count should cover a refinement";
  if (test::countsAllocations()) {
    EXPECT_EQ(allocations, 0u);
  }
}

// A place holds what its keyframe saw: from the keyframe's own pose each of its points lies on the ray of one of
// its camera's keypoints, whatever depth the window's solve gave it. (The keypoints carry 0.5 px of noise, so the
// solved points lie off their rays by about that much: a loop from where the keyframe was would measure that.)
TEST(PlaceRefinement, APlacesPointsLieOnItsKeyframesRays) {
  test::SyntheticSequenceOptions so;
  so.frames = 60;
  PlacesOnSequence run(so);
  auto& [rig, seq, overlap, matcher, odometry_options, odometry, memory, frame] = run;
  for (int i = 0; i < seq.frames(); ++i) {
    seq.fill(i, frame);
    matcher.compute(frame);
    PoseEstimate pose;
    odometry.process(frame, static_cast<uint64_t>(i), pose);
    memory.afterOdometry(frame, static_cast<uint64_t>(i), odometry, pose);
    odometry.startDeferredMapping();
  }
  const Map& local = odometry.map();
  int checked = 0;
  double worst_rad = 0;
  for (int slot = 0; slot < memory.map().capacity(); ++slot) {
    const PlaceKeyframe& place = memory.map().keyframe(slot);
    for (int k = 0; place.alive && k < local.keyframeCapacity(); ++k) {
      const Keyframe& kf = local.keyframe(k);
      if (!kf.alive || kf.frame_index != place.frame_index) continue;
      for (const PlacePoint& p : memory.map().points(slot)) {
        const Vec3 ray = (rig.T_b_c(p.cam).inverse() * p.p_k.cast<double>()).normalized();
        double nearest = M_PI;
        const auto cam = static_cast<std::size_t>(p.cam);
        for (int f = 0; f < kf.features.sets[cam].count; ++f)
          if (kf.features.valid[cam][static_cast<std::size_t>(f)])
            nearest = std::min(
                nearest,
                std::acos(std::clamp(ray.dot(kf.features.bearings[cam][static_cast<std::size_t>(f)]), -1.0, 1.0)));
        worst_rad = std::max(worst_rad, nearest);
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 500);
  EXPECT_LT(worst_rad, 1e-5) << "a place's point lies " << worst_rad << " rad off its keyframe's rays";
}

}  // namespace
}  // namespace mcslam
