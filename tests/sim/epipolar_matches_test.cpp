// ORB matches on rendered images against ground-truth geometry: between two overlapping cameras of the isec rig
// (same instant) and between frames k and k+5 of one camera on the ground trajectory. The essential matrix comes
// from the ground-truth relative pose; matched keypoints are undistorted through the camera model and their
// distance to the epipolar line (normalised coordinates x focal length) must have a median below 0.5 px.
//
// Only matches found on the two finest pyramid levels count: a keypoint of level l is localised to 1.2^l pixels
// (its corner is found on the downscaled image), which is the feature detector's resolution, not the simulator's.
// A ground-truth pose turned by 0.2 degrees must break the check, so it measures the geometry.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "mcslam/features/orb_extractor.hpp"
#include "mcslam/sim/simulation.hpp"

namespace mcslam::sim {
namespace {

struct Match {
  int a, b;
};

// Brute-force Hamming matching, Lowe ratio 0.8, mutual best.
std::vector<Match> matchOrb(const FeatureSet& A, const FeatureSet& B) {
  auto best = [](const FeatureSet& from, int i, const FeatureSet& to, int& second) {
    int b = -1, d1 = 257;
    second = 257;
    for (int j = 0; j < to.count; ++j) {
      const int d = hammingDistance(from.descriptors[i], to.descriptors[j]);
      if (d < d1) {
        second = d1;
        d1 = d;
        b = j;
      } else if (d < second) {
        second = d;
      }
    }
    return std::pair(b, d1);
  };
  std::vector<Match> out;
  for (int i = 0; i < A.count; ++i) {
    int second;
    const auto [j, d] = best(A, i, B, second);
    if (j < 0 || d > 64 || d >= 0.8 * second) continue;
    int unused;
    if (best(B, j, A, unused).first == i) out.push_back({i, j});
  }
  return out;
}

FeatureSet extract(const Image& image) {
  OrbExtractor orb(OrbOptions{}, image.width(), image.height());
  FeatureSet f(OrbOptions{}.max_features);
  EXPECT_EQ(orb.extract(image.view(), f), OrbStatus::kOk);
  return f;
}

constexpr int kFinestLevels = 2;

// Symmetric epipolar distance in pixels of each match on the finest levels; T_a_b maps camera b into camera a.
std::vector<double> epipolarErrors(const FeatureSet& fa, const CameraModel& ca, const FeatureSet& fb,
                                   const CameraModel& cb, const SE3& T_a_b, const std::vector<Match>& matches) {
  const Vec3 t = T_a_b.t.normalized();
  Mat3 tx;
  tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  const Mat3 E = tx * T_a_b.R;  // x_a^T E x_b = 0
  std::vector<double> errors;
  for (const Match& m : matches) {
    if (fa.keypoints[m.a].octave >= kFinestLevels || fb.keypoints[m.b].octave >= kFinestLevels) continue;
    Vec3 ba, bb;
    if (!ca.unproject(Vec2(fa.keypoints[m.a].x, fa.keypoints[m.a].y), ba) ||
        !cb.unproject(Vec2(fb.keypoints[m.b].x, fb.keypoints[m.b].y), bb)) {
      continue;
    }
    const Vec3 xa = ba / ba.z(), xb = bb / bb.z();  // undistorted normalised coordinates
    const Vec3 la = E * xb, lb = E.transpose() * xa;
    const double r = xa.dot(la);
    const double da = std::abs(r) / la.head<2>().norm() * ca.fx();
    const double db = std::abs(r) / lb.head<2>().norm() * cb.fx();
    errors.push_back(0.5 * (da + db));
  }
  return errors;
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

class SimEpipolar : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SimulationConfig cfg;  // isec rig, indoor world, ground robot
    cfg.frames = 40;
    sim_ = new Simulation(cfg);
  }
  static void TearDownTestSuite() {
    delete sim_;
    sim_ = nullptr;
  }

  struct Result {
    double median_px = 0;        // with the ground-truth relative pose
    double median_wrong_px = 0;  // with that pose turned by 0.2 degrees
    int matches = 0;             // on the finest levels
  };

  // Renders (frame_a, cam_a) and (frame_b, cam_b), matches ORB and measures the epipolar errors.
  static Result measure(int frame_a, int cam_a, int frame_b, int cam_b) {
    Image ia, ib;
    sim_->render(frame_a, cam_a, ia);
    sim_->render(frame_b, cam_b, ib);
    const FeatureSet fa = extract(ia), fb = extract(ib);
    const std::vector<Match> m = matchOrb(fa, fb);
    const SE3 T_a_b = sim_->cameraPose(frame_a, cam_a).inverse() * sim_->cameraPose(frame_b, cam_b);
    const CameraModel &ca = sim_->rig().model(cam_a), &cb = sim_->rig().model(cam_b);
    const std::vector<double> e = epipolarErrors(fa, ca, fb, cb, T_a_b, m);
    const SE3 turned(Eigen::AngleAxisd(0.2 * M_PI / 180, Vec3(1, 1, 0).normalized()).toRotationMatrix() * T_a_b.R,
                     T_a_b.t);
    Result r;
    r.matches = static_cast<int>(e.size());
    if (e.empty()) return r;
    r.median_px = median(e);
    r.median_wrong_px = median(epipolarErrors(fa, ca, fb, cb, turned, m));
    return r;
  }

  static Simulation* sim_;
};
Simulation* SimEpipolar::sim_ = nullptr;

// One test for both pairs: building the world is most of the time, and CTest runs every test alone.
TEST_F(SimEpipolar, OverlappingCamerasAndFramesFiveApartMatchOnGroundTruthEpipolarLines) {
  for (const auto& [a, b] : {std::pair(1, 2), std::pair(0, 4)}) {  // neighbours, and the widest baseline
    const Result r = measure(20, a, 20, b);
    ASSERT_GE(r.matches, 100) << "cams " << a << "," << b;
    EXPECT_LT(r.median_px, 0.5) << "cams " << a << "," << b << ": " << r.matches << " matches";
    EXPECT_GT(r.median_wrong_px, 1.0) << "cams " << a << "," << b << ": insensitive to a wrong pose";
    RecordProperty("median_px_cams_" + std::to_string(a) + std::to_string(b), std::to_string(r.median_px));
  }

  // Frames k and k+5 of the centre camera on the ground trajectory.
  const SE3 motion = sim_->cameraPose(30, 2).inverse() * sim_->cameraPose(35, 2);
  ASSERT_GT(motion.t.norm(), 0.2) << "the robot must have moved for the epipolar geometry to mean something";
  const Result r = measure(30, 2, 35, 2);
  ASSERT_GE(r.matches, 100) << "frames 30, 35";
  EXPECT_LT(r.median_px, 0.5) << "frames 30, 35: " << r.matches << " matches";
  EXPECT_GT(r.median_wrong_px, 1.0) << "frames 30, 35: insensitive to a wrong pose";
  RecordProperty("median_px_frames_30_35", std::to_string(r.median_px));
}

}  // namespace
}  // namespace mcslam::sim
