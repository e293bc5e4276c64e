#pragma once
// Synthetic geometry for the back-end's tests and benchmarks: a moving rig observing random
// world points, projected through the full camera models with pixel noise, and a driver that
// slides the solver's window along such a sequence as the odometry will.
// Header-only so that tests/bench can share it without another library.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "mcslam/backend/sliding_window_solver.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/alloc_counter.hpp"
#include "test_support.hpp"

namespace mcslam::backend::testkit {

inline Rig isecRig() { return loadKalibrRig(test::dataPath("calib/isec_5cam_camchain.yaml")); }

struct SceneObservation {
  int keyframe;
  int landmark;
  int camera;
  Vec2 uv;
  double sigma;
  bool outlier = false;
};

struct SceneOptions {
  int num_keyframes = 10;
  int landmarks_per_keyframe = 200;  // sampled in the view of each keyframe
  double step = 0.25;                // metres between keyframes, forward
  double min_depth = 2.0, max_depth = 20.0;
  double pixel_noise = 0.5;          // at sigma = 1 (octave 0)
  int max_octave = 3;                // sigma = 1.2^octave, octave uniform in [0, max_octave]
  int track_min = 3, track_max = 8;  // keyframes a landmark stays trackable (features get lost)
  double detection_probability = 0.8;
  double outlier_fraction = 0.0;  // observations moved by `outlier_pixels`
  double outlier_pixels = 20.0;
  unsigned seed = 1;
};

struct Scene {
  Rig rig;                   // the true rig
  std::vector<SE3> T_w_b;    // true poses
  std::vector<Vec3> points;  // true landmarks
  std::vector<SceneObservation> observations;
  std::vector<std::vector<int>> observations_of_keyframe;
  std::vector<std::vector<int>> observations_of_landmark;
  std::vector<int> num_observations;  // per landmark
};

// Recomputes the per-keyframe and per-landmark observation lists (after editing observations).
inline void indexObservations(Scene& scene) {
  scene.observations_of_keyframe.assign(scene.T_w_b.size(), {});
  scene.observations_of_landmark.assign(scene.points.size(), {});
  scene.num_observations.assign(scene.points.size(), 0);
  for (int i = 0; i < static_cast<int>(scene.observations.size()); ++i) {
    const SceneObservation& ob = scene.observations[i];
    scene.observations_of_keyframe[ob.keyframe].push_back(i);
    scene.observations_of_landmark[ob.landmark].push_back(i);
    ++scene.num_observations[ob.landmark];
  }
}

// Forward motion along the world z axis (the rig looks forward) with lateral and vertical
// sway and a few degrees of yaw and roll, so every pose is different.
inline SE3 trajectoryPose(int k, double step) {
  const double s = k * step;
  const Vec3 t(0.4 * std::sin(0.3 * k), 0.05 * std::sin(0.5 * k), s);
  const Mat3 R = so3Exp(Vec3(0.01 * std::sin(0.7 * k), 0.06 * std::sin(0.25 * k), 0.02 * std::cos(0.4 * k)));
  return {R, t};
}

inline Scene makeScene(const Rig& rig, const SceneOptions& o) {
  Scene scene;
  scene.rig = rig;
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int k = 0; k < o.num_keyframes; ++k) scene.T_w_b.push_back(trajectoryPose(k, o.step));

  // Points: a random pixel of a random camera of keyframe k, at a random depth, trackable over
  // a span of keyframes around k.
  std::vector<std::pair<int, int>> span;
  for (int k = 0; k < o.num_keyframes; ++k) {
    for (int i = 0; i < o.landmarks_per_keyframe; ++i) {
      const int c = std::uniform_int_distribution<int>(0, rig.size() - 1)(rng);
      const CameraModel& m = rig.model(c);
      const Vec2 uv(unit(rng) * (m.width() - 1), unit(rng) * (m.height() - 1));
      Vec3 bearing;
      if (!m.unproject(uv, bearing)) continue;
      const double depth = o.min_depth + (o.max_depth - o.min_depth) * unit(rng);
      scene.points.push_back(scene.T_w_b[k] * (rig.T_b_c(c) * (bearing * depth / bearing.z())));
      const int length = std::uniform_int_distribution<int>(o.track_min, o.track_max)(rng);
      const int first = k - std::uniform_int_distribution<int>(0, length - 1)(rng);
      span.emplace_back(first, first + length);
    }
  }

  for (int k = 0; k < o.num_keyframes; ++k) {
    const SE3 T_b_w = scene.T_w_b[k].inverse();
    for (int l = 0; l < static_cast<int>(scene.points.size()); ++l) {
      if (k < span[l].first || k >= span[l].second) continue;
      for (int c = 0; c < rig.size(); ++c) {
        const Vec3 p_c = rig.T_b_c(c).inverse() * (T_b_w * scene.points[l]);
        if (p_c.z() < 0.5 || p_c.norm() > 1.5 * o.max_depth) continue;
        Vec2 uv;
        if (!rig.model(c).project(p_c, uv) || !rig.model(c).inImage(uv, 2.0)) continue;
        if (unit(rng) > o.detection_probability) continue;
        const int octave = std::uniform_int_distribution<int>(0, o.max_octave)(rng);
        const double sigma = std::pow(1.2, octave);
        uv += o.pixel_noise * sigma * Vec2(gauss(rng), gauss(rng));
        const bool outlier = unit(rng) < o.outlier_fraction;
        if (outlier) {
          const double a = 2 * M_PI * unit(rng);
          uv += o.outlier_pixels * Vec2(std::cos(a), std::sin(a));
        }
        scene.observations.push_back({k, l, c, uv, sigma, outlier});
      }
    }
  }
  indexObservations(scene);
  return scene;
}

// Small deterministic perturbation of a pose: `trans` metres and `rot` radians per axis (std dev).
inline SE3 perturb(const SE3& T, double trans, double rot, std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  Vec6 xi;
  xi << trans * g(rng), trans * g(rng), trans * g(rng), rot * g(rng), rot * g(rng), rot * g(rng);
  return T * SE3::exp(xi);
}

// The rig with camera `camera`'s extrinsic moved by `trans` metres along a fixed direction and
// rotated by `rot` radians about a fixed axis: a calibration error of known size.
inline Rig perturbExtrinsic(const Rig& rig, int camera, double trans, double rot) {
  Rig out = rig;
  const Vec3 dir = Vec3(1, -2, 0.5).normalized();
  const Vec3 axis = Vec3(0.3, 1, -0.4).normalized();
  SE3& T = out.cameras[camera].T_b_c;
  T = T * SE3(so3Exp(axis * rot), dir * trans);
  return out;
}

// Initial guess of one window: every keyframe but the first perturbed, every point moved.
struct WindowGuess {
  std::vector<SE3> T_w_b;
  std::vector<Vec3> points;
};
inline WindowGuess perturbedGuess(const Scene& scene, double pose_trans, double pose_rot, double point_sigma,
                                  unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  WindowGuess guess;
  for (size_t k = 0; k < scene.T_w_b.size(); ++k) {
    guess.T_w_b.push_back(k == 0 ? scene.T_w_b[k] : perturb(scene.T_w_b[k], pose_trans, pose_rot, rng));
  }
  for (const Vec3& p : scene.points) guess.points.push_back(p + point_sigma * Vec3(g(rng), g(rng), g(rng)));
  return guess;
}

// Landmarks with at least two observations (the odometry's rule) enter; returns how many.
// Throws if the solver refuses anything (capacity too small for the scene).
inline int fillSolver(SlidingWindowSolver& solver, const Scene& scene, const WindowGuess& guess) {
  auto check = [](Status s) {
    if (s != Status::Ok) throw std::runtime_error(std::string("fillSolver: ") + statusName(s));
  };
  for (size_t k = 0; k < scene.T_w_b.size(); ++k) check(solver.addKeyframe(static_cast<int64_t>(k), guess.T_w_b[k]));
  int added = 0;
  for (size_t l = 0; l < scene.points.size(); ++l) {
    if (scene.num_observations[l] < 2) continue;
    check(solver.addLandmark(static_cast<int64_t>(l), guess.points[l]));
    ++added;
  }
  for (const SceneObservation& ob : scene.observations) {
    if (scene.num_observations[ob.landmark] < 2) continue;
    check(solver.addObservation(ob.keyframe, ob.landmark, ob.camera, ob.uv, ob.sigma));
  }
  return added;
}

// ---- sliding along a sequence ----

struct SlidingRunOptions {
  int iterations = 10;
  double new_pose_trans = 0.02;  // error of the tracking pose given for a new keyframe
  double new_pose_rot = 0.005;
  double new_point_sigma = 0.05;  // error of a new landmark's triangulation
  bool remove_outliers = true;    // drop what the solver flags, as the odometry will
  bool check_prior = false;       // symmetry and eigenvalues of the prior (allocates)
  unsigned seed = 7;
};

struct SlidingRunResult {
  std::vector<SE3> T_w_b;             // each keyframe's estimate when it left the window (or at the end)
  std::vector<uint64_t> allocations;  // heap allocations during each keyframe's step
  int marginalizations = 0;
  int solves = 0;
  int failed_solves = 0;
  int outliers_removed = 0;
  int refused = 0;                  // calls the solver refused (capacity): must stay 0
  double max_prior_asymmetry = 0;   // max |H - H^T| over the run
  double min_prior_eigenvalue = 0;  // relative to the largest, over the run
  double max_prior_eigenvalue = 0;
};

// Drives the solver as the odometry will: a keyframe with tracking's pose guess, observations
// of landmarks in the window, new landmarks once seen twice in the window, a solve, outlier
// removal, and marginalization of the oldest keyframe when the window is full. The driver
// itself allocates nothing inside the loop, so `allocations` are the solver's.
inline SlidingRunResult runSliding(SlidingWindowSolver& solver, const Scene& scene, const SlidingRunOptions& o) {
  SlidingRunResult result;
  const int N = static_cast<int>(scene.T_w_b.size());
  result.T_w_b.resize(N);
  result.allocations.assign(N, 0);
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> g(0.0, 1.0);
  const size_t L = scene.points.size();
  std::vector<char> in_window(L, 0), retired(L, 0);
  std::vector<int> stamp(L, -1);
  std::vector<int> window_keyframes;
  window_keyframes.reserve(N);
  std::vector<ObservationKey> outliers;
  outliers.reserve(scene.observations.size());
  SE3 previous_estimate;
  for (int k = 0; k < N; ++k) {
    alloc::ThreadScope allocations;
    if (solver.isFull()) {
      const int64_t oldest = *solver.oldestKeyframe();
      solver.keyframePose(oldest, result.T_w_b[oldest]);
      solver.marginalizeOldest();
      ++result.marginalizations;
      for (int64_t id : solver.marginalizedLandmarks()) {
        in_window[id] = 0;
        retired[id] = 1;
      }
      window_keyframes.erase(window_keyframes.begin());
    }
    // Tracking's guess: the true relative motion from the previous estimate, with an error.
    SE3 guess = scene.T_w_b[0];
    if (k > 0) {
      guess = previous_estimate * (scene.T_w_b[k - 1].inverse() * scene.T_w_b[k]);
      guess = perturb(guess, o.new_pose_trans, o.new_pose_rot, rng);
    }
    result.refused += solver.addKeyframe(k, guess) != Status::Ok;
    window_keyframes.push_back(k);

    // Observations of landmarks already in the window; new landmarks once seen twice here.
    for (int idx : scene.observations_of_keyframe[k]) {
      const SceneObservation& ob = scene.observations[idx];
      if (in_window[ob.landmark]) {
        result.refused += solver.addObservation(k, ob.landmark, ob.camera, ob.uv, ob.sigma) != Status::Ok;
      }
    }
    const int first_in_window = window_keyframes.front();  // the window is a contiguous range
    for (int idx : scene.observations_of_keyframe[k]) {
      const int l = scene.observations[idx].landmark;
      if (in_window[l] || retired[l] || stamp[l] == k) continue;
      stamp[l] = k;
      int views = 0;
      for (int i : scene.observations_of_landmark[l]) {
        const int kf = scene.observations[i].keyframe;
        views += kf >= first_in_window && kf <= k;
      }
      if (views < 2) continue;
      const Vec3 noise(g(rng), g(rng), g(rng));
      result.refused += solver.addLandmark(l, scene.points[l] + o.new_point_sigma * noise) != Status::Ok;
      in_window[l] = 1;
      for (int i : scene.observations_of_landmark[l]) {
        const SceneObservation& ob = scene.observations[i];
        if (ob.keyframe >= first_in_window && ob.keyframe <= k) {
          result.refused += solver.addObservation(ob.keyframe, l, ob.camera, ob.uv, ob.sigma) != Status::Ok;
        }
      }
    }
    const SolveSummary s = solver.solve(o.iterations);
    ++result.solves;
    result.failed_solves += s.failed;
    if (o.remove_outliers) {
      for (const ObservationKey& key : solver.outliers()) {
        result.outliers_removed += solver.removeObservation(key) == Status::Ok;
      }
    }
    solver.keyframePose(k, previous_estimate);
    result.allocations[k] = allocations.count();

    if (o.check_prior && result.marginalizations > 0) {
      const Eigen::MatrixXd& H = solver.priorInformation();
      if (H.size() > 0) {
        result.max_prior_asymmetry = std::max(result.max_prior_asymmetry, (H - H.transpose()).cwiseAbs().maxCoeff());
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(H);
        const double top = es.eigenvalues().maxCoeff();
        result.max_prior_eigenvalue = std::max(result.max_prior_eigenvalue, top);
        if (top > 0) {
          result.min_prior_eigenvalue = std::min(result.min_prior_eigenvalue, es.eigenvalues().minCoeff() / top);
        }
      }
    }
  }
  for (int kf : window_keyframes) solver.keyframePose(kf, result.T_w_b[kf]);
  return result;
}

}  // namespace mcslam::backend::testkit
