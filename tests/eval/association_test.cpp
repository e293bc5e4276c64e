#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "eval_test_util.hpp"
#include "mcslam/eval/association.hpp"

using namespace mcslam;
using test::pose;

namespace {

Trajectory stamps(std::initializer_list<double> seconds) {
  Trajectory t;
  for (double s : seconds) t.push_back(pose(s, Vec3::Zero()));
  return t;
}

// evo's matching written as plainly as it reads: for each stamp of the shorter trajectory, the first argmin.
TimeAssociation bruteForce(const Trajectory& ref, const Trajectory& est, double max_diff) {
  TimeAssociation out;
  const bool est_longer = est.size() > ref.size();
  const Trajectory& s = est_longer ? ref : est;
  const Trajectory& l = est_longer ? est : ref;
  for (std::size_t i = 0; i < s.size(); ++i) {
    std::size_t best = 0;
    for (std::size_t j = 1; j < l.size(); ++j) {
      if (std::abs(stampSeconds(l[j].t) - stampSeconds(s[i].t)) <
          std::abs(stampSeconds(l[best].t) - stampSeconds(s[i].t)))
        best = j;
    }
    if (std::abs(stampSeconds(l[best].t) - stampSeconds(s[i].t)) <= max_diff) {
      out.ref.push_back(est_longer ? i : best);
      out.est.push_back(est_longer ? best : i);
    }
  }
  return out;
}

}  // namespace

TEST(Association, ShorterTrajectoryDrivesAndTakesTheNearestStamp) {
  const Trajectory ref = stamps({0.0, 0.1, 0.2, 0.3, 0.4, 0.5});
  const Trajectory est = stamps({0.104, 0.29, 0.47});
  const TimeAssociation a = associateByTime(ref, est, 0.02);
  ASSERT_EQ(a.size(), 2u);  // 0.47 is 0.03 from 0.5: dropped
  EXPECT_EQ(a.est, (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(a.ref, (std::vector<std::size_t>{1, 3}));
}

TEST(Association, WhenTheEstimateIsLongerTheReferenceDrives) {
  const Trajectory ref = stamps({1.0, 2.0});
  const Trajectory est = stamps({0.9, 0.995, 1.002, 1.5, 2.004});
  const TimeAssociation a = associateByTime(ref, est, 0.01);
  EXPECT_EQ(a.ref, (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(a.est, (std::vector<std::size_t>{2, 4}));
}

TEST(Association, OnePoseOfTheLongerTrajectoryMayServeTwo) {
  const Trajectory ref = stamps({0.0, 1.0, 2.0, 3.0});
  const Trajectory est = stamps({0.998, 1.003});
  const TimeAssociation a = associateByTime(ref, est, 0.01);
  EXPECT_EQ(a.ref, (std::vector<std::size_t>{1, 1}));
  EXPECT_EQ(a.est, (std::vector<std::size_t>{0, 1}));
}

TEST(Association, TieGoesToTheFirstIndexAndTheBoundIsInclusive) {
  const Trajectory ref = stamps({0.0, 0.25, 0.5, 0.75, 1.0});
  const Trajectory est = stamps({0.625});  // exactly between 0.5 and 0.75 (binary-exact values)
  const TimeAssociation a = associateByTime(ref, est, 0.125);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a.ref[0], 2u);
  EXPECT_EQ(associateByTime(ref, est, 0.124).size(), 0u);
}

TEST(Association, OffsetShiftsTheEstimate) {
  const Trajectory ref = stamps({10.0, 11.0, 12.0});
  const Trajectory est = stamps({0.0, 1.0});
  EXPECT_EQ(associateByTime(ref, est, 0.01).size(), 0u);
  const TimeAssociation a = associateByTime(ref, est, 0.01, 11.0);
  EXPECT_EQ(a.ref, (std::vector<std::size_t>{1, 2}));
}

TEST(Association, StampSecondsIsTheCorrectlyRoundedDecimal) {
  EXPECT_EQ(stampSeconds(1311868164363181000LL), 1311868164.363181);
  EXPECT_EQ(stampSeconds(1311868163869700000LL), 1311868163.8697);
  EXPECT_EQ(stampSeconds(-1500000000LL), -1.5);
}

TEST(Association, BisectionMatchesTheLinearScanOnSortedAndShuffledStamps) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 5.0);
  for (int trial = 0; trial < 20; ++trial) {
    Trajectory ref, est;
    for (int i = 0; i < 60; ++i) ref.push_back(pose(1e9 + std::round(u(rng) * 1000) / 1000, Vec3::Zero()));
    for (int i = 0; i < 25; ++i) est.push_back(pose(1e9 + u(rng), Vec3::Zero()));
    if (trial % 2 == 0) std::sort(ref.begin(), ref.end(), [](auto& a, auto& b) { return a.t < b.t; });
    const TimeAssociation fast = associateByTime(ref, est, 0.02);
    const TimeAssociation slow = bruteForce(ref, est, 0.02);
    EXPECT_EQ(fast.ref, slow.ref) << "trial " << trial;
    EXPECT_EQ(fast.est, slow.est) << "trial " << trial;
  }
}
