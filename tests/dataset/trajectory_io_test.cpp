#include <gtest/gtest.h>

#include "mcslam/core/error.hpp"
#include "mcslam/dataset/trajectory.hpp"
#include "test_support.hpp"

using namespace mcslam;

namespace {

void expectError(const std::function<void()>& f, std::initializer_list<std::string> fragments) {
  try {
    f();
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const auto& part : fragments)
      EXPECT_NE(msg.find(part), std::string::npos) << "'" << part << "' not in: " << msg;
  }
}

Trajectory sample() {
  Trajectory t;
  for (int i = 0; i < 5; ++i) {
    const Mat3 R = Eigen::AngleAxisd(0.3 * i, Vec3(0.2, 1, -0.4).normalized()).toRotationMatrix();
    t.push_back({1311868164363181123LL + i * 33333333LL, SE3(R, Vec3(0.5 * i, -1.25 + i, 3.0 / (i + 1)))});
  }
  return t;
}

}  // namespace

TEST(TumTrajectory, ParsesStampsExactlyToTheNanosecond) {
  const Trajectory t = parseTumTrajectory(
      "# comment\n"
      "\n"
      "1311868164.363181 0 0 0 0 0 0 1\n"
      "1403636579.763555584 1 2 3 0 0 0 1\n"
      "0.000000001 0 0 0 0 0 0 1\n"
      "5.0000000005 0 0 0 0 0 0 1\n"  // a tenth decimal rounds
      "1e2 0 0 0 0 0 0 1\n",
      "mem");
  ASSERT_EQ(t.size(), 5u);
  EXPECT_EQ(t[0].t, 1311868164363181000LL);
  EXPECT_EQ(t[1].t, 1403636579763555584LL);
  EXPECT_EQ(t[2].t, 1);
  EXPECT_EQ(t[3].t, 5000000001LL);
  EXPECT_EQ(t[4].t, 100000000000LL);
  EXPECT_EQ(t[1].T_w_b.t, Vec3(1, 2, 3));
}

TEST(TumTrajectory, QuaternionOrderIsXyzw) {
  // qx qy qz qw = 0 0 sin(45deg) cos(45deg): 90 degrees about z.
  const Trajectory t = parseTumTrajectory("1 0 0 0 0 0 0.7071067811865476 0.7071067811865476\n", "mem");
  EXPECT_LT((t[0].T_w_b.R * Vec3::UnitX() - Vec3::UnitY()).norm(), 1e-12);
}

TEST(TumTrajectory, WriteReadRoundTripKeepsStampsAndPoses) {
  test::TempDir dir("traj");
  const Trajectory in = sample();
  writeTumTrajectory(dir.file("t.txt"), in);
  const Trajectory out = readTumTrajectory(dir.file("t.txt"));
  ASSERT_EQ(out.size(), in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    EXPECT_EQ(out[i].t, in[i].t);
    EXPECT_LT((out[i].T_w_b.t - in[i].T_w_b.t).norm(), 1e-9);
    EXPECT_LT((out[i].T_w_b.R - in[i].T_w_b.R).norm(), 1e-11);
  }
}

TEST(TumTrajectory, ErrorsNameFileLineAndValue) {
  expectError([] { parseTumTrajectory("1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n", "gt.txt"); },
              {"gt.txt: line 2", "expected 8 values"});
  expectError([] { parseTumTrajectory("abc 0 0 0 0 0 0 1\n", "gt.txt"); }, {"gt.txt: line 1", "timestamp", "'abc'"});
  expectError([] { parseTumTrajectory("1 0 0 x 0 0 0 1\n", "gt.txt"); }, {"gt.txt: line 1", "tz", "'x'"});
  expectError([] { parseTumTrajectory("1 0 0 0 0 0 0 2\n", "gt.txt"); }, {"gt.txt: line 1", "unit length"});
  expectError([] { parseTumTrajectory("1 0 0 0 1 0 0 0 0 1 0 0\n", "gt.txt"); }, {"kitti format"});
  expectError([] { readTumTrajectory("/nonexistent/t.txt"); }, {"/nonexistent/t.txt: cannot open file"});
}

TEST(KittiTrajectory, WriteReadRoundTripWithTimes) {
  test::TempDir dir("traj");
  const Trajectory in = sample();
  writeKittiTrajectory(dir.file("poses.txt"), in);
  std::string times;
  for (const StampedPose& p : in)
    times += std::to_string(p.t / 1000000000) + "." + std::to_string(p.t % 1000000000 + 1000000000).substr(1) + "\n";
  test::writeFile(dir.file("times.txt"), times);
  const Trajectory out = readKittiTrajectory(dir.file("poses.txt"), dir.file("times.txt"));
  ASSERT_EQ(out.size(), in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    EXPECT_EQ(out[i].t, in[i].t);
    EXPECT_LT((out[i].T_w_b.t - in[i].T_w_b.t).norm(), 1e-8);
    EXPECT_LT((out[i].T_w_b.R - in[i].T_w_b.R).norm(), 1e-8);
  }
  // Without times, frame i is at i seconds.
  const Trajectory indexed = readKittiTrajectory(dir.file("poses.txt"));
  EXPECT_EQ(indexed[3].t, 3000000000LL);
}

TEST(KittiTrajectory, ErrorsNameFileAndLine) {
  test::TempDir dir("traj");
  const std::string ok = "1 0 0 0 0 1 0 0 0 0 1 0\n";
  const std::string short_line = test::writeFile(dir.file("a.txt"), ok + "1 0 0 0 0 1 0 0 0 0 1\n");
  expectError([&] { readKittiTrajectory(short_line); }, {short_line + ": line 2", "expected 12 numbers", "got 11"});
  const std::string not_rotation = test::writeFile(dir.file("b.txt"), "2 0 0 0 0 1 0 0 0 0 1 0\n");
  expectError([&] { readKittiTrajectory(not_rotation); }, {not_rotation + ": line 1", "not a rotation"});
  const std::string tum_line = test::writeFile(dir.file("c.txt"), "1 0 0 0 0 0 0 1\n");
  expectError([&] { readKittiTrajectory(tum_line); }, {"tum format"});
  const std::string poses = test::writeFile(dir.file("d.txt"), ok + ok + ok);
  const std::string times = test::writeFile(dir.file("times.txt"), "0.0\n0.1\n");
  expectError([&] { readKittiTrajectory(poses, times); }, {times, "fewer times"});
  const std::string bad_times = test::writeFile(dir.file("bad_times.txt"), "0.0\nsoon\n");
  expectError([&] { readTimesFile(bad_times); }, {bad_times + ": line 2", "'soon'"});
}

TEST(Trajectory, PathLengthSumsTheSteps) {
  Trajectory t;
  for (const Vec3& p : {Vec3(0, 0, 0), Vec3(3, 4, 0), Vec3(3, 4, 2)}) t.push_back({0, SE3(Mat3::Identity(), p)});
  EXPECT_DOUBLE_EQ(pathLength(t), 7.0);
  EXPECT_EQ(pathLength({}), 0.0);
}

TEST(TumTrajectory, TimesBeyondWhatNanosecondsHoldAreErrors) {
  expectError([] { parseTumTrajectory("1e300 0 0 0 0 0 0 1\n", "gt.txt"); },
              {"gt.txt: line 1", "timestamp", "'1e300'"});
  expectError([] { parseTumTrajectory("9223372039.5 0 0 0 0 0 0 1\n", "gt.txt"); }, {"gt.txt: line 1", "timestamp"});
  expectError([] { parseTumTrajectory("-9223372039 0 0 0 0 0 0 1\n", "gt.txt"); }, {"gt.txt: line 1", "timestamp"});
  EXPECT_EQ(parseTumTrajectory("9223372035.5 0 0 0 0 0 0 1\n", "gt.txt").at(0).t, int64_t{9223372035500000000});
}
