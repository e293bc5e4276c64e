#pragma once
// Sliding-window bundle adjustment of the paper's section V (eq. 6-7): keyframe poses T_w_b,
// world landmarks and, optionally, the camera extrinsics T_b_c, over reprojection residuals
// through the full camera model with a robust loss.
//
// - Levenberg-Marquardt on Gauss-Newton normal equations; landmarks eliminated by the Schur
//   complement (3x3 blocks); the reduced camera system (free poses + free extrinsics, 6x6
//   blocks) solved with CHOLMOD. The symbolic analysis is kept while the block structure is
//   unchanged and redone only when it changes.
// - Fixed memory: every pool, matrix and scratch buffer, and CHOLMOD's own memory (routed to an
//   arena), is sized at construction from the capacities; nothing is allocated after warm-up.
// - Gauge: the `gauge_fixed_oldest` oldest keyframes are held fixed, plus any keyframe fixed by
//   id; the reference camera's extrinsic is never refined (it defines the body frame).
// - marginalizeOldest(): the oldest keyframe and the landmarks only it still observes are
//   Schur-complemented into a prior; the oldest keyframe's observations of landmarks that stay
//   in the window are dropped (a dense landmark prior would destroy the landmark structure).
//   The prior therefore constrains what those landmarks told about the extrinsics; its
//   linearization point is kept fixed and the extrinsics it links use first-estimate Jacobians.
//
// Not thread-safe: one thread drives one solver.
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>

#include "mcslam/backend/extrinsic_prior.hpp"
#include "mcslam/backend/robust_loss.hpp"
#include "mcslam/calib/rig.hpp"

namespace mcslam::backend {

struct WindowCapacity {
  int max_keyframes = 10;
  int max_landmarks = 4096;
  int max_observations = 65536;
};

struct SolverOptions {
  RobustLoss loss;              // Huber by default; threshold in units of sigma
  double outlier_chi2 = 5.991;  // |r|^2 above this after a solve marks an outlier (2 dof, 95%)

  bool refine_extrinsics = false;        // turn on for rigs whose calibration was chained
  int reference_camera = 0;              // its extrinsic stays fixed: it anchors the body frame
  ExtrinsicPriorSigmas extrinsic_prior;  // the calibration's uncertainty
  bool first_estimate_jacobians = true;  // for the extrinsics linked to the marginalization prior

  int gauge_fixed_oldest = 1;  // oldest keyframes held fixed (2 for a monocular rig: scale)
  // The window's unit held instead by all its keyframes: the summed distances from the oldest keyframe of
  // those between it and the newest stay as the solve found them (a stiff residual). Two fixed keyframes tie
  // the unit to one pair, which can be 10 cm apart (keyframes at every frame where tracking thins): a 1 cm
  // error in it is 10% of the unit. Needs gauge_fixed_oldest >= 1; with fewer than three keyframes the two
  // oldest are held instead.
  bool hold_window_scale = false;
  // A landmark enters a solve with >= 2 observations and min/max eigenvalue of its 3x3
  // information at least this (parallax); otherwise it is held fixed and left out.
  double min_landmark_conditioning = 1e-9;

  // Levenberg-Marquardt (the trust-region form Ceres uses).
  double initial_trust_radius = 1e4;
  double function_tolerance = 1e-6;   // stop when |d cost| / cost falls below
  double gradient_tolerance = 1e-10;  // stop when max |gradient| falls below
  double parameter_tolerance = 1e-8;  // stop when |dx| <= tol * (|x| + tol)
};

enum class Status {
  Ok,
  UnknownKeyframe,
  UnknownLandmark,
  UnknownObservation,
  DuplicateId,
  CapacityExceeded,
  InvalidCamera,
  InvalidValue,
  EmptyWindow,
};
const char* statusName(Status s);

struct ObservationKey {
  int64_t keyframe_id = 0;
  int64_t landmark_id = 0;
  int camera = 0;
};

struct SolveSummary {
  int iterations = 0;  // linear solves (accepted or not)
  int accepted_steps = 0;
  double initial_cost = 0;  // 0.5 * sum rho(|r|^2) + priors
  double final_cost = 0;
  bool converged = false;     // a tolerance was met (false: iteration budget or failure)
  bool failed = false;        // no valid linearization (nothing to optimize or bad input)
  int symbolic_analyses = 0;  // CHOLMOD analyses run by this solve (0 when the structure held)
  int landmarks_used = 0;     // landmarks that entered the solve
  int landmarks_skipped = 0;  // too few observations or no parallax
  int residuals_used = 0;
  int outliers = 0;  // size of outliers()
};

class SlidingWindowSolver {
 public:
  // Allocates everything the window will ever use. Throws InputError for a bad configuration.
  SlidingWindowSolver(const Rig& rig, const WindowCapacity& capacity, const SolverOptions& options = {});
  ~SlidingWindowSolver();
  SlidingWindowSolver(const SlidingWindowSolver&) = delete;
  SlidingWindowSolver& operator=(const SlidingWindowSolver&) = delete;

  // Empty again, as constructed (the settings changed since included), without allocating: for a map dropped
  // after a tracking loss.
  void clear();

  // ---- window contents (ids are the caller's stable ids) ----
  Status addKeyframe(int64_t id, const SE3& T_w_b);
  Status addLandmark(int64_t id, const Vec3& p_w);
  // sigma_px: measurement standard deviation in pixels (1.2^octave).
  Status addObservation(int64_t keyframe_id, int64_t landmark_id, int camera, const Vec2& uv, double sigma_px);
  Status removeObservation(const ObservationKey& key);
  Status removeLandmark(int64_t id);  // and its observations
  Status setKeyframeFixed(int64_t id, bool fixed);
  // How many oldest keyframes the next solves hold (SolverOptions::gauge_fixed_oldest): 2 holds the window's
  // scale as well, for a map whose scale the window alone cannot keep. InvalidValue below 0.
  Status setGaugeFixedOldest(int count);
  void setHoldWindowScale(bool hold);  // SolverOptions::hold_window_scale, from the next solve
  Status setKeyframePose(int64_t id, const SE3& T_w_b);
  Status setLandmarkPosition(int64_t id, const Vec3& p_w);
  // A new current estimate of a refined camera's extrinsic T_b_c from outside (e.g. a per-camera check). The
  // marginalization prior forgets that extrinsic (it was linearized at the old estimate) and keeps what it knows
  // of the others. Unless keep_calibration_prior, the camera's calibration prior is dropped: the estimate says
  // the calibration is wrong, and with every extrinsic free the rig's scale is set by the translation priors
  // alone, so a wrong one would bias it. InvalidCamera when that extrinsic is not refined.
  Status setExtrinsic(int camera, const SE3& T_b_c, bool keep_calibration_prior = false);
  bool hasCalibrationPrior(int camera) const;

  // ---- optimization ----
  SolveSummary solve(int max_iterations);
  // Observations whose whitened squared residual exceeded outlier_chi2 (or that no longer
  // project) after the last solve. Valid until the next solve, addKeyframe, addLandmark or
  // marginalizeOldest; calling removeObservation() while iterating over it is fine.
  std::span<const ObservationKey> outliers() const;

  // ---- marginalization ----
  // The oldest keyframe and the landmarks only it observes become a prior on the rest.
  Status marginalizeOldest();
  // Landmarks removed by the last marginalizeOldest().
  std::span<const int64_t> marginalizedLandmarks() const;

  // ---- read back ----
  bool keyframePose(int64_t id, SE3& T_w_b) const;
  bool landmarkPosition(int64_t id, Vec3& p_w) const;
  const SE3& extrinsic(int camera) const;  // current T_b_c
  Rig refinedRig() const;                  // the input rig with the current extrinsics (for writing out)
  std::optional<int64_t> oldestKeyframe() const;
  int numKeyframes() const;
  int numLandmarks() const;
  int numObservations() const;
  bool isFull() const;  // no room for another keyframe: marginalize first

  // The marginalization prior on the free extrinsics (6 per free camera, in camera order,
  // reference camera skipped): information matrix, and whether each camera is linked to it.
  const Eigen::MatrixXd& priorInformation() const;
  bool extrinsicInPrior(int camera) const;
  // Bytes of CHOLMOD's arena in use at most so far, and allocations that did not fit (0 expected).
  size_t cholmodArenaPeakBytes() const;
  size_t cholmodArenaOverflows() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace mcslam::backend
