#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "mcslam/core/alloc_counter.hpp"
#include "mcslam/features/multiview_matcher.hpp"
#include "mcslam/features/pair_matcher.hpp"
#include "mcslam/features/track_builder.hpp"
#include "synthetic_rigs.hpp"

using namespace mcslam;

namespace {

constexpr int kCapacity = 1200;

// Keypoints of a synthetic scene: each point gets a random descriptor, seen in a camera as that descriptor
// with a few flipped bits and a noisy pixel; plus distractor keypoints with unrelated descriptors.
// truth[c][k] = scene point index or -1.
struct SyntheticFrame {
  FrameFeatures features;
  std::vector<std::vector<int>> truth;
  std::vector<test::ScenePoint> scene;
};

SyntheticFrame makeFrame(const Rig& rig, int points, int distractors, double noise_px, std::mt19937& rng) {
  SyntheticFrame s;
  s.features.allocate(rig.size(), kCapacity);
  s.truth.assign(rig.size(), {});
  s.scene = test::randomScene(rig, points, 1.0, 25.0, rng);
  std::uniform_int_distribution<uint64_t> bits;
  std::uniform_int_distribution<int> bit(0, 255), octave(0, 2);
  std::normal_distribution<double> noise(0.0, noise_px);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Descriptor> base(s.scene.size());
  std::vector<int> point_octave(s.scene.size());
  for (std::size_t p = 0; p < s.scene.size(); ++p) {
    for (auto& w : base[p]) w = bits(rng);
    point_octave[p] = octave(rng);
  }
  for (int c = 0; c < rig.size(); ++c) {
    struct Item {
      Keypoint kp;
      Descriptor d;
      int truth;
    };
    std::vector<Item> items;
    for (std::size_t p = 0; p < s.scene.size(); ++p) {
      if (!s.scene[p].visible[c]) continue;
      Item it;
      it.kp.x = static_cast<float>(s.scene[p].uv[c].x() + noise(rng));
      it.kp.y = static_cast<float>(s.scene[p].uv[c].y() + noise(rng));
      it.kp.octave = static_cast<int8_t>(point_octave[p]);
      it.d = base[p];
      for (int f = 0; f < 12; ++f) {
        const int b = bit(rng);
        it.d[b / 64] ^= uint64_t{1} << (b % 64);
      }
      it.truth = static_cast<int>(p);
      items.push_back(it);
    }
    for (int k = 0; k < distractors; ++k) {
      Item it;
      it.kp.x = static_cast<float>(u(rng) * (rig.model(c).width() - 1));
      it.kp.y = static_cast<float>(u(rng) * (rig.model(c).height() - 1));
      for (auto& w : it.d) w = bits(rng);
      it.truth = -1;
      items.push_back(it);
    }
    std::shuffle(items.begin(), items.end(), rng);
    items.resize(std::min<std::size_t>(items.size(), kCapacity));
    FeatureSet& set = s.features.sets[c];
    set.count = static_cast<int>(items.size());
    for (std::size_t k = 0; k < items.size(); ++k) {
      set.keypoints[k] = items[k].kp;
      set.descriptors[k] = items[k].d;
      s.truth[c].push_back(items[k].truth);
    }
    s.features.present[c] = 1;
  }
  return s;
}

}  // namespace

TEST(MultiViewMatcher, FindsTheTrueTracksWithMetricDepth) {
  const Rig rig = test::isecRig();
  const OverlapMap overlap(rig, OverlapOptions{});
  MultiViewOptions opt;
  MultiViewMatcher matcher(rig, overlap, opt, kCapacity);
  std::mt19937 rng(21);
  SyntheticFrame s = makeFrame(rig, 700, 200, 0.3, rng);
  matcher.compute(s.features);
  const FrameFeatures& f = s.features;

  int pure = 0, with_point = 0, depth_ok = 0;
  std::vector<int> found(s.scene.size(), 0);
  for (int t = 0; t < f.mv_count; ++t) {
    const MultiViewFeature& mv = f.mv[t];
    uint64_t cams = 0;
    const int p0 = s.truth[f.mv_refs[mv.first].cam][f.mv_refs[mv.first].index];
    bool same = p0 >= 0;
    for (int k = 0; k < mv.size; ++k) {
      const KeypointRef& r = f.mv_refs[mv.first + k];
      EXPECT_FALSE(cams & (uint64_t{1} << r.cam)) << "two keypoints of one camera in a track";
      cams |= uint64_t{1} << r.cam;
      EXPECT_EQ(f.mv_of[r.cam][r.index], t);
      same = same && s.truth[r.cam][r.index] == p0;
    }
    pure += same ? 1 : 0;
    if (same) found[p0] = 1;
    if (mv.metric) {
      ++with_point;
      if (same) {
        const Vec3 truth = s.scene[p0].p_b;
        depth_ok += std::abs(mv.p_b.norm() - truth.norm()) < 0.02 * truth.norm() ? 1 : 0;
      }
    }
  }
  int seen_twice = 0, recovered = 0;
  for (std::size_t p = 0; p < s.scene.size(); ++p) {
    const int views = static_cast<int>(std::count(s.scene[p].visible.begin(), s.scene[p].visible.end(), true));
    if (views >= 2) {
      ++seen_twice;
      recovered += found[p];
    }
  }
  ASSERT_GT(f.mv_count, 100);
  EXPECT_GE(pure, 0.99 * f.mv_count) << pure << " of " << f.mv_count;
  EXPECT_GE(recovered, 0.9 * seen_twice) << recovered << " of " << seen_twice;
  EXPECT_GT(with_point, f.mv_count / 2);
  EXPECT_GE(depth_ok, 0.98 * with_point) << depth_ok << " of " << with_point;
  EXPECT_EQ(matcher.stats().tracks, f.mv_count);
  // Distractors have no partner: they stay mono features.
  int distractor_in_track = 0, distractors = 0;
  for (int c = 0; c < f.cameras(); ++c) {
    for (int k = 0; k < f.sets[c].count; ++k) {
      if (s.truth[c][k] >= 0) continue;
      ++distractors;
      distractor_in_track += f.mv_of[c][k] >= 0 ? 1 : 0;
    }
  }
  EXPECT_LT(distractor_in_track, 0.01 * distractors);
  EXPECT_EQ(f.monoCount() + f.mv_ref_count, f.keypointCount());
}

TEST(MultiViewMatcher, NonOverlappingRigHasOnlyMonoFeatures) {
  const Rig rig = test::ring8Rig(70.0).subset({0, 2, 4, 6});
  OverlapOptions oo;
  oo.min_depth = 1.0;
  const OverlapMap overlap(rig, oo);
  EXPECT_TRUE(overlap.overlappingPairs().empty());
  MultiViewMatcher matcher(rig, overlap, MultiViewOptions{}, kCapacity);
  std::mt19937 rng(22);
  SyntheticFrame s = makeFrame(rig, 400, 100, 0.3, rng);
  matcher.compute(s.features);
  EXPECT_EQ(s.features.mv_count, 0);
  EXPECT_EQ(s.features.monoCount(), s.features.keypointCount());
}

TEST(MultiViewMatcher, AbsentCameraAndNoAllocationAfterWarmUp) {
  const Rig rig = test::isecRig();
  const OverlapMap overlap(rig, OverlapOptions{});
  MultiViewMatcher matcher(rig, overlap, MultiViewOptions{}, kCapacity);
  std::mt19937 rng(23);
  SyntheticFrame s = makeFrame(rig, 500, 100, 0.3, rng);
  matcher.compute(s.features);  // warm-up
  s.features.present[2] = 0;    // camera 2 lost this frame
  alloc::ThreadScope scope;
  matcher.compute(s.features);
  EXPECT_EQ(scope.count(), 0u);
  for (int t = 0; t < s.features.mv_count; ++t) {
    const MultiViewFeature& mv = s.features.mv[t];
    for (int k = 0; k < mv.size; ++k) EXPECT_NE(s.features.mv_refs[mv.first + k].cam, 2);
  }
  EXPECT_GT(s.features.mv_count, 50);
}

// Bearings come from an interpolated grid polished by one Gauss-Newton step: the same as the model's unprojection.
TEST(MultiViewMatcher, BearingsAgreeWithTheCameraModel) {
  for (const Rig& rig : {test::isecRig(), test::ring8Rig(100.0)}) {
    const OverlapMap overlap(rig, OverlapOptions{});
    MultiViewMatcher matcher(rig, overlap, MultiViewOptions{}, kCapacity);
    std::mt19937 rng(24);
    SyntheticFrame s = makeFrame(rig, 500, 300, 0.3, rng);
    matcher.compute(s.features);
    double worst = 0;
    int checked = 0;
    for (int c = 0; c < rig.size(); ++c) {
      for (int k = 0; k < s.features.sets[c].count; ++k) {
        const Keypoint& kp = s.features.sets[c].keypoints[k];
        Vec3 b;
        const bool ok = rig.model(c).unproject(Vec2(kp.x, kp.y), b);
        ASSERT_EQ(ok, s.features.valid[c][k] != 0);
        if (!ok) continue;
        worst = std::max(worst, (b - s.features.bearings[c][k]).norm());
        ++checked;
      }
    }
    EXPECT_GT(checked, 1000);
    EXPECT_LT(worst, 1e-7);  // radians: 1e-4 px at these focal lengths
  }
}

// ---- The matcher's pieces on their own ----

TEST(KeypointBearings, AgreeWithTheCameraModelAnywhereInTheImage) {
  for (const Rig& rig : {test::isecRig(), test::ring8Rig(100.0)}) {
    const KeypointBearings bearings(rig);
    std::mt19937 rng(31);
    for (int c = 0; c < rig.size(); ++c) {
      std::uniform_real_distribution<double> x(-2.0, rig.model(c).width() + 1.0), y(-2.0, rig.model(c).height() + 1.0);
      for (int k = 0; k < 2000; ++k) {
        const Vec2 uv(x(rng), y(rng));
        Vec3 expected, b;
        const bool ok = rig.model(c).unproject(uv, expected);
        ASSERT_EQ(bearings.bearingOf(rig, c, uv, b), ok) << uv.transpose();
        if (ok) {
          EXPECT_LT((b - expected).norm(), 1e-7) << "camera " << c << " at " << uv.transpose();
        }
      }
    }
  }
}

namespace {

// The pair matches of a synthetic frame, with the pairs taken in `order` and pair p on thread p % threads.
std::vector<PairMatch> pairMatches(const Rig& rig, const OverlapMap& overlap, SyntheticFrame& s,
                                   const std::vector<int>& order, int threads) {
  const KeypointBearings bearings(rig);
  PairMatcher pairs(overlap, MultiViewOptions{}, kCapacity, threads);
  pairs.beginFrame();
  for (int c = 0; c < rig.size(); ++c) {
    bearings.compute(rig, s.features, c);
    pairs.prepareCamera(rig, s.features, c);
  }
  for (int p : order) pairs.matchPair(rig, s.features, p, p % threads);
  const std::span<const PairMatch> m = pairs.gather();
  return {m.begin(), m.end()};
}

}  // namespace

TEST(PairMatcher, MutualMatchesOfTrueCornersInsideTheEpipolarGateWhateverThePairOrder) {
  const Rig rig = test::isecRig();
  const OverlapMap overlap(rig, OverlapOptions{});
  std::mt19937 rng(32);
  SyntheticFrame s = makeFrame(rig, 600, 200, 0.3, rng);
  std::vector<int> forward(overlap.overlappingPairs().size());
  for (std::size_t p = 0; p < forward.size(); ++p) forward[p] = static_cast<int>(p);
  const std::vector<PairMatch> matches = pairMatches(rig, overlap, s, forward, 1);
  ASSERT_GT(matches.size(), 300u);

  const MultiViewOptions opt;
  int correct = 0, previous_pair = -1;
  std::vector<std::vector<int>> used(rig.size(), std::vector<int>(kCapacity, -1));  // pair that matched a keypoint
  for (const PairMatch& m : matches) {
    const auto& pairs = overlap.overlappingPairs();
    const int pair = static_cast<int>(
        std::find(pairs.begin(), pairs.end(), std::make_pair<int, int>(m.cam_a, m.cam_b)) - pairs.begin());
    ASSERT_LT(pair, static_cast<int>(pairs.size())) << "a match between cameras that do not overlap";
    EXPECT_GE(pair, previous_pair) << "matches not in pair order";
    previous_pair = pair;
    EXPECT_NE(used[m.cam_a][m.kp_a], pair) << "keypoint matched twice in one pair";
    EXPECT_NE(used[m.cam_b][m.kp_b], pair) << "keypoint matched twice in one pair";
    used[m.cam_a][m.kp_a] = used[m.cam_b][m.kp_b] = pair;
    EXPECT_LE(m.distance, opt.max_hamming);
    correct += s.truth[m.cam_a][m.kp_a] >= 0 && s.truth[m.cam_a][m.kp_a] == s.truth[m.cam_b][m.kp_b] ? 1 : 0;
    // Inside the gate: the ray of b is within the gate's angle of the epipolar plane of a.
    const Vec3 e = (rig.T_b_c(m.cam_b).t - rig.T_b_c(m.cam_a).t).normalized();
    const Vec3 da = rig.T_b_c(m.cam_a).R * s.features.bearings[m.cam_a][m.kp_a];
    const Vec3 db = rig.T_b_c(m.cam_b).R * s.features.bearings[m.cam_b][m.kp_b];
    const Keypoint& kb = s.features.sets[m.cam_b].keypoints[m.kp_b];
    const double fj = 0.5 * (rig.model(m.cam_b).fx() + rig.model(m.cam_b).fy());
    EXPECT_LE(std::abs(e.cross(da).normalized().dot(db)),
              opt.epipolar_px * std::pow(opt.octave_scale, kb.octave) / fj + 1e-6);
  }
  EXPECT_GE(correct, 0.99 * static_cast<double>(matches.size())) << correct << " of " << matches.size();

  // The same matches with the pairs matched backwards on two threads' scratch.
  std::vector<int> backward(forward.rbegin(), forward.rend());
  const std::vector<PairMatch> again = pairMatches(rig, overlap, s, backward, 2);
  ASSERT_EQ(again.size(), matches.size());
  for (std::size_t k = 0; k < matches.size(); ++k) {
    EXPECT_TRUE(again[k].cam_a == matches[k].cam_a && again[k].cam_b == matches[k].cam_b &&
                again[k].kp_a == matches[k].kp_a && again[k].kp_b == matches[k].kp_b &&
                again[k].distance == matches[k].distance)
        << "match " << k;
  }
}

// The true matches of a frame, plus worse false ones that would put two keypoints of one camera into a track:
// the tracks are the true points (the false matches lose to the better true ones), and the builder allocates
// nothing once warm.
TEST(TrackBuilder, JoinsTrueMatchesIntoTracksAndRefusesTwoKeypointsOfOneCamera) {
  const Rig rig = test::isecRig();
  const OverlapMap overlap(rig, OverlapOptions{});
  std::mt19937 rng(33);
  SyntheticFrame s = makeFrame(rig, 500, 0, 0.2, rng);
  const KeypointBearings bearings(rig);
  for (int c = 0; c < rig.size(); ++c) bearings.compute(rig, s.features, c);
  // Keypoint of point p in camera c (or -1).
  auto keypointOf = [&](int c, int p) {
    const auto it = std::find(s.truth[c].begin(), s.truth[c].end(), p);
    return it == s.truth[c].end() ? -1 : static_cast<int>(it - s.truth[c].begin());
  };
  std::vector<PairMatch> matches;
  int false_matches = 0;
  for (const auto& [i, j] : overlap.overlappingPairs()) {
    int previous = -1;  // the last point seen by both: its keypoint in j is the false partner of the next one's in i
    for (int p = 0; p < static_cast<int>(s.scene.size()); ++p) {
      const int a = keypointOf(i, p), b = keypointOf(j, p);
      if (a < 0 || b < 0) continue;
      matches.push_back(PairMatch{static_cast<int16_t>(i), static_cast<int16_t>(j), a, b, 10});
      if (previous >= 0 && p % 5 == 0) {
        matches.push_back(PairMatch{static_cast<int16_t>(i), static_cast<int16_t>(j), a, keypointOf(j, previous), 40});
        ++false_matches;
      }
      previous = p;
    }
  }
  ASSERT_GT(false_matches, 20);
  TrackBuilder builder(overlap, MultiViewOptions{}, kCapacity);
  FrameFeatures& f = s.features;
  for (int round = 0; round < 2; ++round) {
    alloc::ThreadScope scope;
    builder.merge(f, matches, false);
    EXPECT_EQ(builder.alignTaskCount(), 0);
    f.mv_count = f.mv_ref_count = 0;
    builder.emitTracks(rig, f);
    if (round == 1) {
      EXPECT_EQ(scope.count(), 0u);
    }
  }
  EXPECT_EQ(builder.stats().pair_matches, static_cast<int>(matches.size()));
  EXPECT_EQ(builder.stats().tracks, f.mv_count);
  int seen_twice = 0, metric = 0, depth_ok = 0;
  for (const test::ScenePoint& p : s.scene) seen_twice += std::count(p.visible.begin(), p.visible.end(), true) >= 2;
  for (int t = 0; t < f.mv_count; ++t) {
    const MultiViewFeature& mv = f.mv[t];
    const int p0 = s.truth[f.mv_refs[mv.first].cam][f.mv_refs[mv.first].index];
    uint64_t cams = 0;
    for (int k = 0; k < mv.size; ++k) {
      const KeypointRef& r = f.mv_refs[mv.first + k];
      EXPECT_FALSE(cams & (uint64_t{1} << r.cam)) << "two keypoints of one camera in track " << t;
      cams |= uint64_t{1} << r.cam;
      EXPECT_EQ(s.truth[r.cam][r.index], p0) << "track " << t << " joins two points";
    }
    if (!mv.metric) continue;
    ++metric;
    depth_ok += (mv.p_b - s.scene[p0].p_b).norm() < 0.02 * s.scene[p0].p_b.norm() ? 1 : 0;
  }
  EXPECT_GE(f.mv_count, 0.95 * seen_twice) << f.mv_count << " tracks of " << seen_twice << " points seen twice";
  EXPECT_GT(metric, f.mv_count / 2);
  EXPECT_GE(depth_ok, 0.98 * metric) << depth_ok << " of " << metric;
}
