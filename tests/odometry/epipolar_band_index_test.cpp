// The band index must return exactly the bearings a brute-force epipolar test accepts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "mcslam/odometry/epipolar_band_index.hpp"

using namespace mcslam;

namespace {

Vec3 randomUnit(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return Vec3(g(rng), g(rng), g(rng)).normalized();
}

// What the index promises: within the octave range, |n . d| <= gate[octave] and d on the ray's half-plane.
std::set<int> bruteForce(const Vec3& axis, const std::vector<Vec3>& dirs, const std::vector<int>& octaves,
                         const Vec3& ray, int lo, int hi, const double* gate) {
  std::set<int> out;
  const Vec3 e = axis.normalized();
  const Vec3 n = e.cross(ray).normalized();
  const Vec3 perp = ray - e * e.dot(ray);
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    if (octaves[i] < lo || octaves[i] > hi) continue;
    if (std::abs(n.dot(dirs[i])) <= gate[octaves[i]] && perp.dot(dirs[i]) > 0) out.insert(static_cast<int>(i));
  }
  return out;
}

}  // namespace

TEST(EpipolarBandIndex, FindsExactlyTheBearingsOnTheRaysEpipolarHalfPlane) {
  std::mt19937 rng(7);
  constexpr int kOctaves = 8;
  double gate[kOctaves];
  for (int o = 0; o < kOctaves; ++o) gate[o] = 2.0 * std::pow(1.2, o) / 450.0;  // 2 px at f = 450
  const int n = 3000;
  EpipolarBandIndex index(n, kOctaves);
  int compared = 0, found = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 axis = randomUnit(rng) * (0.05 + trial * 0.1);
    std::vector<Vec3> dirs(n);
    std::vector<int> octaves(n);
    ASSERT_TRUE(index.begin(axis));
    for (int i = 0; i < n; ++i) {
      // A tenth of the bearings near the baseline (the epipole of forward motion), the rest anywhere.
      dirs[i] = i % 10 == 0 ? (axis.normalized() + 0.03 * randomUnit(rng)).normalized() : randomUnit(rng);
      octaves[i] = static_cast<int>(rng() % kOctaves);
      index.add(i, dirs[i], octaves[i]);
    }
    index.finish();
    for (int q = 0; q < 200; ++q) {
      // Rays that have partners: a perturbed bearing of the set, or any direction.
      const Vec3 ray = q % 2 == 0 ? (dirs[rng() % n] + 0.002 * randomUnit(rng)).normalized() : randomUnit(rng);
      const int lo = static_cast<int>(rng() % kOctaves) - 2, hi = lo + 4;
      std::set<int> got;
      const bool has_plane = index.forEachOnPlane(ray, lo, hi, gate, [&](int32_t id, const float* d) {
        EXPECT_FLOAT_EQ(d[0], static_cast<float>(dirs[id].x()));
        EXPECT_TRUE(got.insert(id).second) << "returned twice: " << id;
      });
      ASSERT_TRUE(has_plane);
      const std::set<int> want = bruteForce(axis, dirs, octaves, ray, std::max(lo, 0), hi, gate);
      // Float bearings may flip a test that sits exactly on its boundary (the gate, or the edge of the
      // half-plane); nothing else may differ.
      std::vector<int> differ;
      std::set_symmetric_difference(got.begin(), got.end(), want.begin(), want.end(), std::back_inserter(differ));
      const Vec3 e = axis.normalized();
      const Vec3 nn = e.cross(ray).normalized();
      const Vec3 perp = ray - e * e.dot(ray);
      for (const int id : differ) {
        const bool on_gate = std::abs(std::abs(nn.dot(dirs[id])) - gate[octaves[id]]) < 1e-6;
        const bool on_edge = std::abs(perp.dot(dirs[id])) < 1e-6;
        EXPECT_TRUE(on_gate || on_edge) << "trial " << trial << " bearing " << id << " returned " << got.count(id);
      }
      ++compared;
      found += static_cast<int>(want.size());
    }
  }
  EXPECT_EQ(compared, 4000);
  EXPECT_GT(found, 4000);  // the queries did have partners to find
}

TEST(EpipolarBandIndex, ARayAlongTheBaselineOrCoincidentCentresHaveNoPlane) {
  EpipolarBandIndex index(10, 8);
  EXPECT_FALSE(index.begin(Vec3::Zero()));
  ASSERT_TRUE(index.begin(Vec3(0, 0, 2)));
  index.add(0, Vec3(1, 0, 0), 0);
  index.finish();
  const double gate[8] = {0.01, 0.01, 0.01, 0.01, 0.01, 0.01, 0.01, 0.01};
  int calls = 0;
  EXPECT_FALSE(index.forEachOnPlane(Vec3(0, 0, 1), 0, 7, gate, [&](int32_t, const float*) { ++calls; }));
  EXPECT_TRUE(index.forEachOnPlane(Vec3(1, 0, 0.1).normalized(), 0, 7, gate, [&](int32_t, const float*) { ++calls; }));
  EXPECT_EQ(calls, 1);
  // The opposite half-plane is another epipolar curve (behind the baseline): not a partner.
  EXPECT_TRUE(index.forEachOnPlane(Vec3(-1, 0, 0.1).normalized(), 0, 7, gate, [&](int32_t, const float*) { ++calls; }));
  EXPECT_EQ(calls, 1);
}
