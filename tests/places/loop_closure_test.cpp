// Loop closure end to end: a 3-camera rig drives 6 m down the start of the indoor route, turns round, drives back
// and turns round again at its start (mcslam-sim renders the route from a TUM file). Back at the start it sees the
// first place again: the loop closes, every closure joins keyframes that are truly near each other (no false
// closure), the world revision counts the corrections, and the corrected keyframe trajectory ends nearer its start
// than the run without loop closure.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <regex>

#include "alloc_testing.hpp"
#include "mcslam/dataset/trajectory.hpp"
#include "test_support.hpp"

namespace mcslam {
namespace {

long jsonInt(const std::string& json, const std::string& key) {
  const std::size_t at = json.find("\"" + key + "\":");
  return at == std::string::npos ? -1000 : std::stol(json.substr(at + key.size() + 3));
}

// The pose of `gt` nearest in time to t.
const SE3& nearest(const Trajectory& gt, double t) {
  std::size_t best = 0;
  for (std::size_t i = 0; i < gt.size(); ++i)
    if (std::abs(toSeconds(gt[i].t) - t) < std::abs(toSeconds(gt[best].t) - t)) best = i;
  return gt[best].T_w_b;
}

// Out 6 m along the route's first heading, a half turn in place, back, and a half turn at the start; 10 Hz.
void writeOutAndBack(const Trajectory& start, const std::string& path) {
  const SE3 T0 = start.front().T_w_b;
  Vec3 forward = start.back().T_w_b.t - T0.t;
  forward.z() = 0;
  forward.normalize();
  std::ofstream out(path);
  double t = 1.0;
  const auto emit = [&](const Vec3& p, double yaw) {
    const Eigen::Quaterniond q(so3Exp(Vec3(0, 0, yaw)) * T0.R);
    out << std::fixed << t << ' ' << p.x() << ' ' << p.y() << ' ' << p.z() << ' ' << q.x() << ' ' << q.y() << ' '
        << q.z() << ' ' << q.w() << '\n';
    t += 0.1;
  };
  const double length = 6.0, speed = 0.6, turn_rate = M_PI / 4;  // m, m/s, rad/s
  const auto drive = [&](const Vec3& from, const Vec3& direction, double yaw) {
    for (double s = 0; s < length; s += speed * 0.1) emit(from + s * direction, yaw);
  };
  const auto turn = [&](const Vec3& at, double yaw0) {
    for (double a = 0; a < M_PI; a += turn_rate * 0.1) emit(at, yaw0 + a);
  };
  drive(T0.t, forward, 0);
  turn(T0.t + length * forward, 0);
  drive(T0.t + length * forward, -forward, M_PI);
  turn(T0.t, M_PI);
  for (int i = 0; i < 20; ++i) emit(T0.t, 2 * M_PI);  // stand at the start, facing as at first
}

class LoopClosure : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>("loop_closure");
    std::string out;
    const std::string sim = "--rig isec --world indoor --no-depth --quiet ";
    const std::string start = test::cachedRender(sim + "--cameras 0 --frames 11", {}, &out);
    ASSERT_FALSE(start.empty()) << out;
    const std::string route = dir_->file("route.txt");
    writeOutAndBack(readTumTrajectory(start + "/groundtruth.txt"), route);
    seq_ = test::cachedRender(sim + "--cameras 1,2,3 --trajectory file:" + route, {route}, &out);
    ASSERT_FALSE(seq_.empty()) << out;
  }
  static void TearDownTestSuite() { dir_.reset(); }

  struct Run {
    Trajectory keyframes;
    std::string stats, log;
  };
  static Run run(const std::string& tag, const std::string& options) {
    Run r;
    const std::string kf = dir_->file(tag + ".kf.tum"), stats = dir_->file(tag + ".json");
    EXPECT_EQ(test::runCommand(test::binPath("mcslam-run") + " --dataset " + seq_ + " --quiet --keyframes " + kf +
                                   " --stats " + stats + " " + options,
                               &r.log),
              0)
        << r.log;
    r.keyframes = readTumTrajectory(kf);
    r.stats = test::readFile(stats);
    test::expectRunAllocatedNothing(r.stats);
    return r;
  }
  static std::unique_ptr<test::TempDir> dir_;
  static std::string seq_;  // the rendered route, shared by the suite's test processes
};

std::unique_ptr<test::TempDir> LoopClosure::dir_;
std::string LoopClosure::seq_;

// The rig loses track in both half turns. Relocalized, it is back in the first map's frame at the start (the
// kidnap test below); so that the loop closer has to join the maps, this run starts a new map at once after a loss
// (relocalization_timeout_s 0): back at the start, the map begun in the final turn is 2 m and 33 deg off. Starting
// those maps (the two-frame initialization of this rig without overlap) allocates nothing either.
// Every closure the run logged joins two keyframes that are within 1 m and 30 degrees of each other in truth, and
// the world revision counts them; returns how many there were.
long expectOnlyTrueClosures(const std::string& log, const std::string& stats, const Trajectory& gt) {
  const long closures = jsonInt(stats, "loop_closures");
  EXPECT_EQ(jsonInt(stats, "world_revision"), closures);
  const std::regex line(R"(t = ([0-9.]+) s\) sees keyframe [0-9]+ \(t = ([0-9.]+) s\))");
  int seen = 0;
  for (auto it = std::sregex_iterator(log.begin(), log.end(), line); it != std::sregex_iterator(); ++it) {
    const SE3& a = nearest(gt, std::stod((*it)[1]));
    const SE3& b = nearest(gt, std::stod((*it)[2]));
    EXPECT_LT((a.t - b.t).norm(), 1.0) << it->str();
    EXPECT_LT(rotationAngle(a.R, b.R), 30 * M_PI / 180) << it->str();
    ++seen;
  }
  EXPECT_EQ(seen, closures);
  return closures;
}

double endError(const Trajectory& keyframes) { return (keyframes.back().T_w_b.t - keyframes.front().T_w_b.t).norm(); }

TEST_F(LoopClosure, TheRouteClosesAtItsStartWithNoFalseClosure) {
  const Trajectory gt = readTumTrajectory(seq_ + "/groundtruth.txt");
  const std::string config =
      test::writeFile(dir_->file("no_relocalization.yaml"), "slam:\n  places:\n    relocalization_timeout_s: 0\n");
  const Run closed = run("closed", "--config " + config);
  const Run open = run("open", "--config " + config + " --no-loop-closure");
  const long closures = expectOnlyTrueClosures(closed.log, closed.stats, gt);
  EXPECT_GE(closures, 1) << closed.log;
  EXPECT_EQ(jsonInt(open.stats, "loop_closures"), 0);
  // The corrected keyframes end where they started, at least as well as without the closure.
  std::printf("closures %ld, end error closed %.4f m, open %.4f m\n", closures, endError(closed.keyframes),
              endError(open.keyframes));
  EXPECT_LE(endError(closed.keyframes), endError(open.keyframes) + 1e-3);
  EXPECT_LT(endError(closed.keyframes), 0.05);
}

// As mcslamd runs it: the detection and the correction are taken the first frame they are ready (a frame waits only
// for a detection whose map it must write). The loop still closes, truly, and no thread allocates.
TEST_F(LoopClosure, TheLiveLoopCloserClosesTheSameRoute) {
  const Trajectory gt = readTumTrajectory(seq_ + "/groundtruth.txt");
  const std::string config =
      test::writeFile(dir_->file("no_relocalization.yaml"), "slam:\n  places:\n    relocalization_timeout_s: 0\n");
  const Run live = run("live", "--config " + config + " --live");
  const long closures = expectOnlyTrueClosures(live.log, live.stats, gt);
  EXPECT_GE(closures, 1) << live.log;
  EXPECT_GE(jsonInt(live.stats, "loop_detection_waits"), 0) << live.stats;
  std::printf("live: closures %ld, detection waits %ld, end error %.4f m\n", closures,
              jsonInt(live.stats, "loop_detection_waits"), endError(live.keyframes));
  EXPECT_LT(endError(live.keyframes), 0.05);
}

// Whether the run published its pose at time t (seconds) as tracking, from its stats' state changes.
bool trackedAt(const std::string& stats, double t) {
  const std::regex change(R"re("frame": [0-9]+,\s*"t": ([0-9.e+-]+),\s*"state": "([a-z_]+)")re");
  bool tracking = false;
  for (auto it = std::sregex_iterator(stats.begin(), stats.end(), change); it != std::sregex_iterator(); ++it) {
    if (std::stod((*it)[1]) > t + 1e-6) break;
    tracking = (*it)[2] == "tracking";
  }
  return tracking;
}

// A kidnap: 2.4 m out, the rig is carried to the way back, 1.3 m from the start and facing it (18 s of frames
// skipped). The odometry must not take the new view for its old map (a consensus of chance matches): it loses
// track (facing away from what it mapped, past relocalization_timeout_s: a new odometry map starts), and place
// memory finds the rig again in the same world frame once it sees the start: standing there at the end, facing as
// at first, its published pose is the first one's.
TEST_F(LoopClosure, AKidnappedRigIsNotTrackedFalselyAndIsFoundAgain) {
  const Trajectory gt = readTumTrajectory(seq_ + "/groundtruth.txt");
  const Run kidnapped = run("kidnap", "--skip 40-219 --out " + dir_->file("kidnap.tum"));
  const Trajectory published = readTumTrajectory(dir_->file("kidnap.tum"));
  const double kidnap_t = toSeconds(gt[220].t);                           // the first frame after the skipped ones
  EXPECT_FALSE(trackedAt(kidnapped.stats, kidnap_t)) << kidnapped.stats;  // not taken for the old place
  // Once, and right: a relocalization on a chance consensus (during the final turn) would come first.
  EXPECT_EQ(jsonInt(kidnapped.stats, "relocalizations"), 1) << kidnapped.stats;
  ASSERT_FALSE(published.empty());
  EXPECT_TRUE(trackedAt(kidnapped.stats, toSeconds(published.back().t))) << kidnapped.stats;
  // Before the kidnap and from the relocalization on, the poses are the truth's (related by the first pose) to
  // decimetres. (In between, past relocalization_timeout_s, a new odometry map goes on from where the motion model
  // left the rig: off by the kidnap until it is recognized.)
  const SE3 gt_from_world = nearest(gt, toSeconds(published.front().t)) * published.front().T_w_b.inverse();
  const double found_t = toSeconds(gt[static_cast<std::size_t>(jsonInt(kidnapped.stats, "last_relocalized_frame"))].t);
  int checked = 0;
  for (const StampedPose& p : published) {
    const double t = toSeconds(p.t);
    if (!trackedAt(kidnapped.stats, t) || (t > kidnap_t - 1e-6 && t < found_t - 1e-6)) continue;
    const Vec3 error = (gt_from_world * p.T_w_b).t - nearest(gt, toSeconds(p.t)).t;
    EXPECT_LT(error.norm(), 0.3) << "t = " << toSeconds(p.t);
    ++checked;
  }
  EXPECT_GT(checked, 55);
  const SE3 drift = published.front().T_w_b.inverse() * published.back().T_w_b;
  std::printf("kidnap: back at the start, %.3f m and %.2f deg from the first pose\n", drift.t.norm(),
              so3Log(drift.R).norm() * 180 / M_PI);
  EXPECT_LT(drift.t.norm(), 0.2);
  EXPECT_LT(so3Log(drift.R).norm(), 3 * M_PI / 180);
}

}  // namespace
}  // namespace mcslam
