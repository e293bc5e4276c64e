#pragma once
// Two-frame scenes for the relative-pose tests and benchmarks: matches of a rig between two body frames, with
// pixel noise and gross outliers, and the rigs and motions they use.
#include <algorithm>
#include <cmath>
#include <vector>

#include "mcslam/geometry/relative_pose.hpp"
#include "pose_scenes.hpp"

namespace mcslam::test {

// Bearing of world point X seen by camera `cam` of the rig at body pose T_w_b, through the pixel
// with noise. False when it is not in the image.
inline bool noisyBearing(const Rig& rig, int cam, const SE3& T_w_b, const Vec3& X, double noise_px, SceneRandom& r,
                         Vec3& bearing) {
  Vec2 uv;
  if (!rig.model(cam).project(rig.T_b_c(cam).inverse() * (T_w_b.inverse() * X), uv)) return false;
  if (!rig.model(cam).inImage(uv)) return false;
  uv += Vec2(r.gaussian(noise_px), r.gaussian(noise_px));
  return rig.model(cam).unproject(uv, bearing);
}

struct TwoFrames {
  SE3 T_1_2;
  std::vector<RelativeCorrespondence> matches;
  std::vector<uint8_t> is_inlier;
};

// Matches between frame 1 (the world) and frame 2 = T_1_2. cross_camera: the point is seen by
// another camera in frame 2 (overlapping rigs); otherwise by the same camera.
inline TwoFrames makeTwoFrames(const Rig& rig, const SE3& T_1_2, int n, double outlier_fraction, double noise_px,
                               SceneRandom& r, bool cross_camera = false) {
  TwoFrames f;
  f.T_1_2 = T_1_2;
  const int num_outliers = static_cast<int>(std::round(n * outlier_fraction));
  int attempts = 0;
  while (static_cast<int>(f.matches.size()) < n && ++attempts < 100000) {
    RelativeCorrespondence m;
    m.camera1 = r.index(rig.size());
    m.camera2 = cross_camera ? (m.camera1 + 1) % rig.size() : m.camera1;
    const Vec3 X = pointSeenBy(rig, m.camera1, SE3(), r, 2.0, 12.0);
    if (!noisyBearing(rig, m.camera1, SE3(), X, noise_px, r, m.bearing1)) continue;
    if (!noisyBearing(rig, m.camera2, T_1_2, X, noise_px, r, m.bearing2)) continue;
    const bool outlier = static_cast<int>(f.matches.size()) < num_outliers;
    if (outlier) {
      // Another point's bearing in frame 2, far from the right one.
      const Vec3 Y = pointSeenBy(rig, m.camera2, T_1_2, r, 2.0, 12.0);
      Vec3 wrong;
      if (!noisyBearing(rig, m.camera2, T_1_2, Y, 0.0, r, wrong) ||
          std::acos(std::min(1.0, wrong.dot(m.bearing2))) < 0.05)
        continue;
      m.bearing2 = wrong;
    }
    f.matches.push_back(m);
    f.is_inlier.push_back(outlier ? 0 : 1);
  }
  return f;
}

// The non-overlapping rig with its cameras twice as far from the centre (about 0.3 m: a robot).
inline Rig wideNonOverlappingRig() {
  Rig rig = nonOverlappingRig();
  for (RigCamera& c : rig.cameras) c.T_b_c.t *= 2.0;
  return rig;
}

// Three overlapping cameras whose centres are not on one line (a stereo pair and one camera above).
inline Rig trinocularRig() {
  Rig rig = stereoRig();
  rig.cameras.push_back(rigCamera("cam2", pinholeRadtan(), {0.0, 0.01, 0.0}, {0.06, -0.08, 0.0}));
  return rig;
}

inline SE3 motion(double yaw_deg, const Vec3& t) {
  return SE3(so3Exp(Vec3(0.1, 1.0, 0.05).normalized() * yaw_deg * M_PI / 180), t);
}

// Distance between essential matrices, which are defined up to sign (both of unit norm).
inline double essentialDistance(const Mat3& a, const Mat3& b) {
  return std::min((a.normalized() - b.normalized()).norm(), (a.normalized() + b.normalized()).norm());
}

}  // namespace mcslam::test
