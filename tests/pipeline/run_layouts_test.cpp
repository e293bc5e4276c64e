// One rendered sequence written in the three layouts mcslam reads (native ASL, EuRoC, KITTI) goes through
// mcslam-run unchanged: the readers hand the pipeline the same rig, images and times, so the trajectories
// agree with each other and with the ground truth each layout carries.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "mcslam/dataset/dataset.hpp"
#include "mcslam/dataset/trajectory.hpp"
#include "mcslam/eval/trajectory_metrics.hpp"
#include "test_support.hpp"

using namespace mcslam;

namespace {

constexpr int kFrames = 60;

std::string bin(const std::string& tool) { return test::binPath(tool); }

class RunLayouts : public ::testing::Test {
 protected:
  // Rendered once for the suite: a rectified stereo pair (KITTI 00's intrinsics and baseline), indoor loop start.
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>("run_layouts");
    const std::string asl = dir_->file("asl");
    std::string out;
    const int code = test::runCommand(
        bin("mcslam-sim") + " --rig " + test::dataPath("calib/rectified_stereo_camchain.yaml") +
            " --world indoor --frames " + std::to_string(kFrames) + " --no-depth --quiet --seed 3 --out " + asl,
        &out);
    ASSERT_EQ(code, 0) << out;
    for (const char* layout : {"euroc", "kitti"}) {
      ASSERT_EQ(
          test::runCommand(
              bin("mcslam-dataset") + " convert " + asl + " --layout " + layout + " --out " + dir_->file(layout), &out),
          0)
          << out;
    }
  }
  static void TearDownTestSuite() { dir_.reset(); }

  static Trajectory run(const std::string& layout, const std::string& extra = "") {
    const std::string tag = layout + (extra.empty() ? "" : "_sequential");
    const std::string traj = dir_->file(tag + ".tum");
    std::string out;
    EXPECT_EQ(test::runCommand(bin("mcslam-run") + " --dataset " + dir_->file(layout) + " --quiet --out " + traj +
                                   " --stats " + dir_->file(tag + ".json") + " " + extra,
                               &out),
              0)
        << out;
    return readTumTrajectory(traj);
  }

  static std::unique_ptr<test::TempDir> dir_;
};

std::unique_ptr<test::TempDir> RunLayouts::dir_;

double maxPositionDifference(const Trajectory& a, const Trajectory& b) {
  double worst = 0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    worst = std::max(worst, (a[i].T_w_b.t - b[i].T_w_b.t).norm());
  return worst;
}

// The integer after the first "key": in a JSON text (-1 when absent).
long jsonInt(const std::string& json, const std::string& key) {
  const std::size_t at = json.find("\"" + key + "\":");
  return at == std::string::npos ? -1 : std::stol(json.substr(at + key.size() + 3));
}

}  // namespace

TEST_F(RunLayouts, EveryLayoutGivesTheSameTrajectoryAndItMatchesItsGroundTruth) {
  const Trajectory asl = run("asl"), euroc = run("euroc"), kitti = run("kitti");
  ASSERT_EQ(asl.size(), static_cast<std::size_t>(kFrames));
  ASSERT_EQ(euroc.size(), asl.size());
  ASSERT_EQ(kitti.size(), asl.size());
  for (std::size_t i = 0; i < asl.size(); ++i) {
    EXPECT_EQ(euroc[i].t, asl[i].t);
    EXPECT_EQ(kitti[i].t, asl[i].t);
  }
  // Same inputs up to the last digits of the written calibration: the same trajectory (to well under a millimetre).
  EXPECT_LT(maxPositionDifference(asl, euroc), 1e-4);
  EXPECT_LT(maxPositionDifference(asl, kitti), 1e-4);
  // The front-end of the next frame overlaps the odometry of this one by default; one after the other, the very
  // same trajectory (the stages share no state).
  run("asl", "--no-overlap");
  EXPECT_EQ(test::readFile(dir_->file("asl_sequential.tum")), test::readFile(dir_->file("asl.tum")));
  // The stats file says when tracking started (frame 0 initializes from the multi-view features of one frame).
  const std::string stats = test::readFile(dir_->file("asl.json"));
  EXPECT_NE(stats.find("\"state_changes\": [\n    {\n      \"frame\": 0,"), std::string::npos) << stats;
  EXPECT_NE(stats.find("\"state\": \"tracking\""), std::string::npos) << stats;
  // And each matches the ground truth its own layout carries (TUM body poses, EuRoC state csv, KITTI poses.txt).
  for (const auto& [layout, trajectory] :
       {std::pair{"asl", &asl}, std::pair{"euroc", &euroc}, std::pair{"kitti", &kitti}}) {
    const Dataset ds = Dataset::open(dir_->file(layout));
    ASSERT_TRUE(ds.groundTruth()) << layout;
    const ApeResult ape = computeApe(*ds.groundTruth(), *trajectory, {});
    EXPECT_EQ(ape.errors.size(), static_cast<std::size_t>(kFrames)) << layout;
    EXPECT_GT(ape.data.ref_path_length, 2.0) << layout;  // the robot really moved
    EXPECT_LT(ape.stats.rmse, 0.02) << layout << ": ATE " << ape.stats.rmse << " m over " << ape.data.ref_path_length
                                    << " m";
  }
}

// A trajectory whose unit is not metres says so: one camera of the pair tracks up to scale, and the runner tells
// when tracking starts and again at the end; the pair (metric from its first frame) says neither.
TEST_F(RunLayouts, TheRunnerSaysWhenTheTrajectoryIsNotMetric) {
  std::string one, pair;
  const std::string common = bin("mcslam-run") + " --dataset " + dir_->file("asl") + " --frames 30 --out " +
                             dir_->file("unit.tum") + " --stats " + dir_->file("unit.json");
  ASSERT_EQ(test::runCommand(common + " --cameras 0", &one), 0) << one;
  EXPECT_NE(one.find("tracking up to scale (one camera)"), std::string::npos) << one;
  EXPECT_NE(one.find("one camera: the trajectory's unit is arbitrary"), std::string::npos) << one;
  // Every frame with a pose is counted up to scale: those tracked, those interpolated before initialization and
  // the two frames the map started from (its reference and the frame it started at).
  const std::string one_stats = test::readFile(dir_->file("unit.json"));
  EXPECT_EQ(jsonInt(one_stats, "map_starts_posed_afterwards"), 1) << one_stats;
  EXPECT_EQ(jsonInt(one_stats, "frames_unknown_scale"), jsonInt(one_stats, "tracking") +
                                                            jsonInt(one_stats, "interpolated_before_initialization") +
                                                            2 * jsonInt(one_stats, "map_starts_posed_afterwards"))
      << one_stats;
  EXPECT_EQ(jsonInt(one_stats, "frames_roughly_metric"), 0) << one_stats;
  EXPECT_GT(jsonInt(one_stats, "frames_unknown_scale"), 20) << one_stats;
  ASSERT_EQ(test::runCommand(common, &pair), 0) << pair;
  EXPECT_EQ(pair.find("up to scale"), std::string::npos) << pair;
  EXPECT_EQ(pair.find("unit is arbitrary"), std::string::npos) << pair;
  EXPECT_EQ(jsonInt(test::readFile(dir_->file("unit.json")), "frames_unknown_scale"), 0);
  // The pair again, with a metric bar beyond what its common points reach (as 6 cm apart before a far scene).
  std::string far;
  const std::string config =
      test::writeFile(dir_->file("far.yaml"), "slam:\n  initialization:\n    metric_disparity_px: 5000\n");
  ASSERT_EQ(test::runCommand(common + " --config " + config, &far), 0) << far;
  EXPECT_EQ(far.find("up to scale"), std::string::npos) << far;
  EXPECT_NE(far.find("the trajectory's unit is the metre to within tens of percent"), std::string::npos) << far;
  const std::string far_stats = test::readFile(dir_->file("unit.json"));
  EXPECT_GT(jsonInt(far_stats, "frames_roughly_metric"), 20) << far_stats;
  EXPECT_EQ(jsonInt(far_stats, "frames_roughly_metric"), jsonInt(far_stats, "frames_unknown_scale")) << far_stats;
}

// A run that gives no frame a pose (one camera cannot initialize from one frame) fails and says why, instead of
// exiting 0 with an empty trajectory.
TEST_F(RunLayouts, ARunThatGivesNoPoseAtAllFailsAndSaysWhy) {
  std::string out;
  const std::string trajectory = dir_->file("none.tum");
  EXPECT_EQ(
      test::runCommand(
          bin("mcslam-run") + " --dataset " + dir_->file("asl") + " --cameras 0 --frames 1 --out " + trajectory, &out),
      1)
      << out;
  EXPECT_NE(out.find("no frame of 1 got a pose"), std::string::npos) << out;
  EXPECT_EQ(test::readFile(trajectory).rfind("# ", 0), 0u) << "the (empty) trajectory is still written";
}

// The per-frame times say which frames a percentile is made of: one line per frame given to the SLAM, numbered as
// the stats file numbers them and by the dataset's index (after --start), with the state and the keyframe flag the
// stats file counts, and each stage's time.
TEST_F(RunLayouts, FrameTimesListEveryFrameWithItsStateAndWhetherItMadeAKeyframe) {
  const std::string csv_path = dir_->file("times.csv"), stats_path = dir_->file("times.json");
  std::string out;
  ASSERT_EQ(test::runCommand(bin("mcslam-run") + " --dataset " + dir_->file("asl") + " --quiet --start 10 --frames 30" +
                                 " --out " + dir_->file("times.tum") + " --stats " + stats_path + " --frame-times " +
                                 csv_path,
                             &out),
            0)
      << out;
  std::istringstream csv(test::readFile(csv_path));
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  EXPECT_EQ(line,
            "frame,dataset_frame,t,state,keyframe,features_ms,tracking_ms,optimization_ms,place_memory_ms,total_ms");
  const Trajectory trajectory = readTumTrajectory(dir_->file("times.tum"));
  std::size_t rows = 0;
  long keyframes = 0;
  while (std::getline(csv, line)) {
    std::istringstream row(line);
    std::vector<std::string> f;
    for (std::string field; std::getline(row, field, ',');) f.push_back(field);
    ASSERT_EQ(f.size(), 10u) << line;
    EXPECT_EQ(std::stoul(f[0]), rows) << line;       // the run's count, as the stats file's state changes
    EXPECT_EQ(std::stoul(f[1]), 10 + rows) << line;  // the dataset's index
    ASSERT_LT(rows, trajectory.size());
    EXPECT_NEAR(std::stod(f[2]), toSeconds(trajectory[rows].t), 1e-6) << line;
    EXPECT_EQ(f[3], "tracking") << line;  // a stereo pair tracks from its first frame
    keyframes += std::stol(f[4]);
    for (int stage = 5; stage < 9; ++stage) {
      EXPECT_GE(std::stod(f[stage]), 0.0) << line;
      EXPECT_LE(std::stod(f[stage]), std::stod(f[9]) + 1e-3) << line << ": a stage longer than the frame";
    }
    ++rows;
  }
  EXPECT_EQ(rows, 30u);
  EXPECT_EQ(keyframes, jsonInt(test::readFile(stats_path), "keyframes"));
  EXPECT_GT(keyframes, 1);
}

// --skip takes several ranges (a kidnap, then frames a camera dropped right after it): those frames are never given
// to the SLAM; a range that is not one is named, and nothing runs.
TEST_F(RunLayouts, FramesSkippedInSeveralRangesAreNeverGivenAndABadRangeIsNamed) {
  const std::string csv_path = dir_->file("skip.csv");
  const std::string run = bin("mcslam-run") + " --dataset " + dir_->file("asl") + " --quiet --frames 30 --out " +
                          dir_->file("skip.tum") + " --frame-times " + csv_path;
  std::string out;
  ASSERT_EQ(test::runCommand(run + " --skip 3-5,9,20-21", &out), 0) << out;
  std::istringstream csv(test::readFile(csv_path));
  std::string line;
  std::getline(csv, line);  // header
  std::vector<unsigned long> given;
  while (std::getline(csv, line)) given.push_back(std::stoul(line.substr(line.find(',') + 1)));
  std::vector<unsigned long> expected;
  for (unsigned long i = 0; i < 30; ++i)
    if (!(i >= 3 && i <= 5) && i != 9 && !(i >= 20 && i <= 21)) expected.push_back(i);
  EXPECT_EQ(given, expected);
  for (const char* bad : {"3-5,,9", "7-", "-7", "9-3", "3-5,"}) {
    EXPECT_EQ(test::runCommand(run + " --skip '" + bad + "'", &out), 2) << bad << ": " << out;
    EXPECT_NE(out.find("--skip '" + std::string(bad) + "'"), std::string::npos) << out;
    EXPECT_NE(out.find("is not a frame range"), std::string::npos) << out;
  }
}

// An output that cannot be written (a full disk: /dev/full) fails the run and names the file, whichever output it
// is; before, the stats and the extrinsics were lost with exit code 0.
TEST_F(RunLayouts, AnOutputThatCannotBeWrittenFailsTheRunAndIsNamed) {
  const std::string run =
      bin("mcslam-run") + " --dataset " + dir_->file("asl") + " --quiet --frames 5 --out " + dir_->file("full.tum");
  for (const char* option : {"--stats", "--extrinsics", "--keyframes", "--frame-times"}) {
    std::string out;
    EXPECT_EQ(test::runCommand(run + " " + option + " /dev/full", &out), 2) << option << ": " << out;
    EXPECT_NE(out.find("/dev/full"), std::string::npos) << option << ": " << out;
  }
}

// One camera of a rendered pair (140 frames), 4 s of a loop: long enough for a loss that lasts.
class RunAfterALoss : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>("run_after_loss");
    std::string out;
    ASSERT_EQ(
        test::runCommand(bin("mcslam-sim") + " --rig " + test::dataPath("calib/rectified_stereo_camchain.yaml") +
                             " --world indoor --frames 140 --no-depth --quiet --seed 3 --out " + dir_->file("asl"),
                         &out),
        0)
        << out;
    std::ofstream config(dir_->file("no_places.yaml"));
    config << "slam:\n  places:\n    enabled: false\n";  // no relocalization: a loss ends in a new map
  }
  static void TearDownTestSuite() { dir_.reset(); }

  // mcslam-run on `cameras` (camera 0 by default) with `options`; the stats file's text.
  static std::string run(const std::string& tag, const std::string& options, const std::string& cameras = "0") {
    std::string out;
    EXPECT_EQ(
        test::runCommand(bin("mcslam-run") + " --dataset " + dir_->file("asl") + " --cameras " + cameras + " --quiet " +
                             options + " --out " + dir_->file(tag + ".tum") + " --stats " + dir_->file(tag + ".json"),
                         &out),
        0)
        << out;
    return test::readFile(dir_->file(tag + ".json"));
  }

  static std::unique_ptr<test::TempDir> dir_;
};

std::unique_ptr<test::TempDir> RunAfterALoss::dir_;

// After a loss that lasts, one camera starts a new map from two frames; the frames from its reference to its start
// had no pose of their own and are written afterwards, from the new map's keyframes, where the rig was: the
// trajectory has no jump there (the reference's keyframe pose places them, not the origin).
TEST_F(RunAfterALoss, ANewMapFromTwoFramesWritesItsFirstFramesWhereTheRigWas) {
  const std::string stats = run("new_map", "--black 40-50 --config " + dir_->file("no_places.yaml"));
  ASSERT_EQ(jsonInt(stats, "map_starts_posed_afterwards"), 2) << stats;  // the first map, and the one after the loss
  const Trajectory t = readTumTrajectory(dir_->file("new_map.tum"));
  ASSERT_GT(t.size(), 100u);
  std::vector<double> steps;
  for (std::size_t i = 1; i < t.size(); ++i) steps.push_back((t[i].T_w_b.t - t[i - 1].T_w_b.t).norm());
  std::vector<double> sorted = steps;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  for (std::size_t i = 0; i < steps.size(); ++i) {
    EXPECT_LT(steps[i], 4 * median) << "between poses " << i << " and " << i + 1 << " (median step " << median << ")";
  }
}

// A loss longer than place memory's timeout sends the odometry back to initialization, and the first frame after
// the blackout both starts an attempt and is relocalized: the relocalization drops the attempt in flight and the
// rig is tracked from there to the end in the same map.
TEST_F(RunAfterALoss, ARelocalizationDropsTheInitializationAttemptInFlight) {
  const std::string stats = run("relocalized", "--black 40-80");
  EXPECT_EQ(jsonInt(stats, "relocalizations"), 1) << stats;
  EXPECT_EQ(jsonInt(stats, "last_relocalized_frame"), 81) << stats;
  EXPECT_EQ(jsonInt(stats, "initializations"), 1) << stats;  // the first map only
  // The 59 frames from the relocalization on, and the first map's before the blackout.
  EXPECT_GE(jsonInt(stats, "tracking"), 59 + 10) << stats;
}

// A roughly metric map (the stereo pair with a metric bar beyond its disparities) stays so through a blackout: the
// frame relocalized in it says so like every other (its record is made anew by the relocalization).
TEST_F(RunAfterALoss, ARelocalizedFrameOfARoughlyMetricMapSaysSo) {
  const std::string config =
      test::writeFile(dir_->file("far.yaml"), "slam:\n  initialization:\n    metric_disparity_px: 5000\n");
  const std::string stats = run("roughly", "--black 40-60 --config " + config, "0,1");
  EXPECT_GE(jsonInt(stats, "relocalizations"), 1) << stats;
  const std::size_t posed = readTumTrajectory(dir_->file("roughly.tum")).size();
  ASSERT_GT(posed, 100u);
  EXPECT_EQ(jsonInt(stats, "frames_unknown_scale"), static_cast<long>(posed)) << stats;
  EXPECT_EQ(jsonInt(stats, "frames_roughly_metric"), static_cast<long>(posed)) << stats;
}
