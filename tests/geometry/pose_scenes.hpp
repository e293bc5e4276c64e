#pragma once
// Synthetic rigs and scenes for the pose-solver tests and benchmarks: every rig shape the solvers
// must handle, seeded random poses and points, exact or noisy observations.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "mcslam/geometry/absolute_pose.hpp"

namespace mcslam::test {

inline CameraModel pinholeRadtan() {
  return CameraModel(640, 480, 420.0, 418.0, 319.5, 241.0, Distortion::RadTan, {-0.28, 0.07, 2e-4, -1e-4});
}
inline CameraModel fisheyeEquidistant() {
  return CameraModel(752, 480, 300.0, 300.0, 375.0, 240.0, Distortion::Equidistant, {0.01, -0.004, 0.001, -0.0002});
}

inline RigCamera rigCamera(const std::string& name, const CameraModel& model, const Vec3& yaw_pitch_roll,
                           const Vec3& position) {
  const Mat3 R =
      (Eigen::AngleAxisd(yaw_pitch_roll[0], Vec3::UnitY()) * Eigen::AngleAxisd(yaw_pitch_roll[1], Vec3::UnitX()) *
       Eigen::AngleAxisd(yaw_pitch_roll[2], Vec3::UnitZ()))
          .toRotationMatrix();
  return {name, model, SE3(R, position), 0};
}

// One camera; the body frame is offset from it so that "central" is not "body = camera".
inline Rig monoRig() {
  Rig rig;
  rig.cameras.push_back(rigCamera("cam0", pinholeRadtan(), {0.05, -0.02, 0.01}, {0.03, -0.1, 0.2}));
  return rig;
}
inline Rig stereoRig() {
  Rig rig;
  rig.cameras.push_back(rigCamera("cam0", pinholeRadtan(), {0, 0, 0}, {0, 0, 0}));
  rig.cameras.push_back(rigCamera("cam1", pinholeRadtan(), {0.01, 0.0, -0.005}, {0.12, 0.0, 0.001}));
  return rig;
}
// Three cameras looking forward, left and backward-right: no overlap.
inline Rig nonOverlappingRig() {
  Rig rig;
  rig.cameras.push_back(rigCamera("cam0", pinholeRadtan(), {0, 0, 0}, {0, 0, 0.1}));
  rig.cameras.push_back(rigCamera("cam1", pinholeRadtan(), {-M_PI / 2, 0.05, 0}, {-0.15, 0.02, 0}));
  rig.cameras.push_back(rigCamera("cam2", fisheyeEquidistant(), {3 * M_PI / 4, -0.1, 0.02}, {0.12, 0, -0.12}));
  return rig;
}
// Six fisheyes around a ring of 0.25 m radius, looking outward, slightly tilted.
inline Rig ringRig() {
  Rig rig;
  for (int i = 0; i < 6; ++i) {
    const double yaw = i * M_PI / 3;
    rig.cameras.push_back(rigCamera("cam" + std::to_string(i), i % 2 ? fisheyeEquidistant() : pinholeRadtan(),
                                    {yaw, 0.1 * (i % 3 - 1), 0},
                                    {0.25 * std::sin(yaw), 0.02 * i, 0.25 * std::cos(yaw)}));
  }
  return rig;
}

struct NamedRig {
  std::string name;
  Rig rig;
};
inline std::vector<NamedRig> allRigShapes() {
  return {
      {"mono", monoRig()}, {"stereo", stereoRig()}, {"non_overlapping_3", nonOverlappingRig()}, {"ring_6", ringRig()}};
}

class SceneRandom {
 public:
  explicit SceneRandom(uint32_t seed) : rng_(seed) {}
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
  int index(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }
  double gaussian(double sigma) { return std::normal_distribution<double>(0.0, sigma)(rng_); }
  Vec3 unitVector() {
    Vec3 v(gaussian(1), gaussian(1), gaussian(1));
    return v.normalized();
  }
  SE3 pose(double max_translation) {
    return SE3(so3Exp(unitVector() * uniform(0, M_PI)),
               Vec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)) * max_translation);
  }
  std::mt19937& engine() { return rng_; }

 private:
  std::mt19937 rng_;
};

// A world point seen by camera `cam` at pixel uv (inside the image) and depth in [near, far].
inline Vec3 pointSeenBy(const Rig& rig, int cam, const SE3& T_w_b, SceneRandom& r, double near = 2.0,
                        double far = 20.0) {
  const CameraModel& m = rig.model(cam);
  Vec3 bearing;
  for (;;) {
    const Vec2 uv(r.uniform(10, m.width() - 11), r.uniform(10, m.height() - 11));
    if (m.unproject(uv, bearing)) break;
  }
  return T_w_b * (rig.T_b_c(cam) * (bearing * r.uniform(near, far)));
}

// Observation of world point X by camera `cam` at body pose T_w_b, with Gaussian pixel noise.
// False when the point does not project into the image.
inline bool observe(const Rig& rig, int cam, const SE3& T_w_b, const Vec3& X_w, double noise_px, double sigma_px,
                    SceneRandom& r, PoseObservation& obs) {
  const Vec3 p_c = rig.T_b_c(cam).inverse() * (T_w_b.inverse() * X_w);
  Vec2 uv;
  if (!rig.model(cam).project(p_c, uv)) return false;
  uv += Vec2(r.gaussian(noise_px), r.gaussian(noise_px));
  return makePoseObservation(rig, cam, uv, X_w, sigma_px, obs);
}

struct PoseScene {
  SE3 T_w_b;
  std::vector<PoseObservation> observations;
  std::vector<uint8_t> is_inlier;
};

// n observations spread over all cameras; a fraction `outliers` are gross mismatches (the world
// point of another place, at least min_outlier_px away from where it should project).
inline PoseScene makePoseScene(const Rig& rig, int n, double outlier_fraction, double noise_px, double sigma_px,
                               SceneRandom& r, double min_outlier_px = 30.0) {
  PoseScene s;
  s.T_w_b = r.pose(5.0);
  const int num_outliers = static_cast<int>(std::round(n * outlier_fraction));
  while (static_cast<int>(s.observations.size()) < n) {
    const bool outlier = static_cast<int>(s.observations.size()) < num_outliers;
    const int cam = r.index(rig.size());
    PoseObservation o;
    if (!observe(rig, cam, s.T_w_b, pointSeenBy(rig, cam, s.T_w_b, r), noise_px, sigma_px, r, o)) continue;
    if (outlier) {
      // Pair the keypoint with a wrong map point (seen by a random camera elsewhere).
      const Vec3 wrong = pointSeenBy(rig, r.index(rig.size()), s.T_w_b, r);
      Vec2 uv;
      const Vec3 p_c = rig.T_b_c(cam).inverse() * (s.T_w_b.inverse() * wrong);
      if (rig.model(cam).project(p_c, uv) && (uv - o.pixel).norm() < min_outlier_px) continue;
      o.point_w = wrong;
    }
    s.observations.push_back(o);
    s.is_inlier.push_back(outlier ? 0 : 1);
  }
  // Shuffle so that outliers are not grouped.
  for (int i = n - 1; i > 0; --i) {
    const int j = r.index(i + 1);
    std::swap(s.observations[i], s.observations[j]);
    std::swap(s.is_inlier[i], s.is_inlier[j]);
  }
  return s;
}

inline double rotationErrorDeg(const SE3& a, const SE3& b) { return rotationAngle(a.R, b.R) * 180.0 / M_PI; }
inline double translationError(const SE3& a, const SE3& b) { return (a.t - b.t).norm(); }

}  // namespace mcslam::test
