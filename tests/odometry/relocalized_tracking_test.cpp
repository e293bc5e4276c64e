// The first frame tracked after a relocalization has no motion model: the odometry predicts it where the
// relocalized frame was. When the rig moved on past a repeated pattern, that stale prediction finds the pattern's
// next copy where the last one was, and a consensus of those matches says the rig stood still. The test puts a
// small repeated pattern (one tenth of what the rig sees) into a room of unique texture and moves the rig sideways
// by the pattern's period between the relocalized frame and the next: the next frame must be tracked where it is.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "mcslam/features/multiview_matcher.hpp"
#include "mcslam/odometry/map_seed.hpp"
#include "mcslam/odometry/odometry.hpp"
#include "synthetic_sequence.hpp"

namespace mcslam {
namespace {

constexpr int kMaxFeatures = 800;
constexpr int kUnique = 8000;

// Textured points with their descriptors, in a frame with y down (the body's convention at the origin).
struct World {
  std::vector<Vec3> points;
  std::vector<Descriptor> descriptors;
};

Descriptor randomDescriptor(std::mt19937& rng) {
  std::uniform_int_distribution<uint64_t> bits;
  Descriptor d;
  for (auto& w : d) w = bits(rng);
  return d;
}

// A 10 m room of unique texture around the origin, and on the wall ahead a pattern of `patch` points repeated
// `copies` times along x every `period` metres.
World roomWithRepeatedPattern(int unique, int patch, int copies, double period, std::mt19937& rng) {
  World w;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < unique; ++i) {
    const double a = u(rng), b = u(rng), wall = 5.0 + 0.5 * u(rng);
    Vec3 p;
    switch (i % 4) {
      case 0: p = Vec3(5 * a, 1.5 * b, wall); break;
      case 1: p = Vec3(5 * a, 1.5 * b, -wall); break;
      case 2: p = Vec3(wall, 1.5 * b, 5 * a); break;
      default: p = Vec3(-wall, 1.5 * b, 5 * a); break;
    }
    w.points.push_back(p);
    w.descriptors.push_back(randomDescriptor(rng));
  }
  std::vector<Vec3> tile;
  std::vector<Descriptor> tile_descriptors;
  for (int i = 0; i < patch; ++i) {
    tile.emplace_back(0.5 * period * (u(rng) + 1.0) / 2.0, 0.4 * u(rng), 4.0 + 0.1 * u(rng));
    tile_descriptors.push_back(randomDescriptor(rng));
  }
  for (int k = 0; k < copies; ++k) {
    for (int i = 0; i < patch; ++i) {
      w.points.push_back(tile[i] + Vec3((k - copies / 2) * period, 0, 0));
      w.descriptors.push_back(tile_descriptors[i]);
    }
  }
  return w;
}

// The rig's view of the world from T_w_b: per camera the nearest points it sees, with pixel noise and a few
// descriptor bits flipped; point_of[c][k] is keypoint k's point.
void view(const Rig& rig, const World& w, const SE3& T_w_b, std::mt19937& rng, FrameFeatures& out,
          std::vector<std::vector<int>>& point_of) {
  std::normal_distribution<double> noise(0.0, 0.5);
  std::uniform_int_distribution<int> bit(0, 255);
  out.clear();
  point_of.assign(static_cast<std::size_t>(rig.size()), {});
  for (int c = 0; c < rig.size(); ++c) {
    out.present[c] = 1;
    const SE3 T_c_w = (T_w_b * rig.T_b_c(c)).inverse();
    std::vector<std::pair<double, int>> seen;  // depth, point
    for (int p = 0; p < static_cast<int>(w.points.size()); ++p) {
      const Vec3 pc = T_c_w * w.points[static_cast<std::size_t>(p)];
      Vec2 uv;
      if (pc.z() > 0.2 && rig.model(c).project(pc, uv) && rig.model(c).inImage(uv, 20)) seen.emplace_back(pc.z(), p);
    }
    std::sort(seen.begin(), seen.end());
    FeatureSet& set = out.sets[c];
    for (const auto& [depth, p] : seen) {
      if (set.count == set.capacity()) break;
      Vec2 uv;
      rig.model(c).project(T_c_w * w.points[static_cast<std::size_t>(p)], uv);
      Keypoint kp;
      kp.x = static_cast<float>(uv.x() + noise(rng));
      kp.y = static_cast<float>(uv.y() + noise(rng));
      kp.octave = 0;
      Descriptor d = w.descriptors[static_cast<std::size_t>(p)];
      for (int f = 0; f < 10; ++f) {
        const int b = bit(rng);
        d[b / 64] ^= uint64_t{1} << (b % 64);
      }
      set.keypoints[set.count] = kp;
      set.descriptors[set.count] = d;
      ++set.count;
      point_of[static_cast<std::size_t>(c)].push_back(p);
    }
  }
  out.t = static_cast<Timestamp>(0);
}

TEST(RelocalizedTracking, TheFirstFrameAfterARelocalizationIsNotTakenForTheRepeatedPatternsNextCopy) {
  const Rig rig = test::isecRig();
  std::mt19937 rng(3);
  const double period = 0.3;  // at 4 m, 30-40 px: past the search radius around the stale prediction
  const World world = roomWithRepeatedPattern(kUnique, /*patch=*/12, /*copies=*/7, period, rng);
  OverlapMap overlap(rig, OverlapOptions{});
  MultiViewMatcher matcher(rig, overlap, MultiViewOptions{}, kMaxFeatures);
  Odometry odometry(rig, OdometryOptions{}, kMaxFeatures);
  FrameFeatures frame(rig.size(), kMaxFeatures);
  std::vector<std::vector<int>> point_of;

  // Relocalized: every keypoint of the frame matched to its true point.
  const SE3 T_w_a;
  view(rig, world, T_w_a, rng, frame, point_of);
  matcher.compute(frame);
  std::vector<MapSeed> seeds;
  int pattern_seen = 0;
  for (int c = 0; c < rig.size(); ++c) {
    for (int k = 0; k < frame.sets[c].count; ++k) {
      const int p = point_of[static_cast<std::size_t>(c)][static_cast<std::size_t>(k)];
      seeds.push_back({static_cast<int16_t>(c), k, world.points[static_cast<std::size_t>(p)],
                       world.descriptors[static_cast<std::size_t>(p)], true});
      pattern_seen += p >= kUnique ? 1 : 0;
    }
  }
  std::printf("seeds %zu, of the pattern %d\n", seeds.size(), pattern_seen);
  ASSERT_GT(pattern_seen, 100);  // a consensus of the pattern's copies is far above any tracking threshold
  ASSERT_LT(pattern_seen, static_cast<int>(seeds.size()) / 5);
  PoseEstimate out;
  odometry.relocalize(frame, 0, T_w_a, seeds, out);
  ASSERT_EQ(out.state, TrackingState::Tracking);

  // The next frame, one period to the right.
  const SE3 T_w_b(Mat3::Identity(), Vec3(period, 0, 0));
  view(rig, world, T_w_b, rng, frame, point_of);
  frame.t = static_cast<Timestamp>(100'000'000);
  matcher.compute(frame);
  odometry.process(frame, 1, out);
  ASSERT_EQ(out.state, TrackingState::Tracking);
  EXPECT_LT((out.T_w_b.t - T_w_b.t).norm(), 0.02) << "tracked at " << out.T_w_b.t.transpose();
  EXPECT_LT(so3Log(out.T_w_b.R).norm(), 0.2 * M_PI / 180);
}

}  // namespace
}  // namespace mcslam
