#pragma once
// Metric scale of a map that a rig of non-overlapping cameras started up to scale. Two frames cannot fix it
// with lever arms of centimetres (the relative pose is nearly degenerate in scale); a window of keyframes
// that turns can: the cameras' centres then move differently from the body, and only one scale explains the
// reprojections through the metric extrinsics.
//
// Over a window of the map's newest keyframes (extrinsics held at the calibration, the oldest keyframe fixed):
//  1. coarse: the profile of the cost over log s. At each factor the keyframe positions (relative to the
//     oldest) and the landmarks are multiplied by it and the window is re-fitted with u held there. Scaling
//     alone, poses otherwise held, favours the map's own unit: tracking and the back-end fitted the poses in
//     that unit, absorbing what the lever arms disagree with, so every other unit costs more until the poses
//     are re-fitted. The profile brings a map whose unit is far off into the basin; it only chooses the basin,
//     so it fits an even sample of the landmarks (kProfileLandmarks);
//  2. fine: Levenberg-Marquardt on the whole window (poses and landmarks, landmarks eliminated by the Schur
//     complement) from there, only steps that lower the cost taken (undamped Gauss-Newton can jump into a
//     state that looks certain and is far off). The scale is u = log of the summed keyframe
//     distances from the oldest one; its sigma is the MARGINAL one (g^T S^-1 g over the reduced pose system),
//     inflated by the reduced chi-square: holding the poses would give a sigma many times too small, as the
//     poses absorb much of a scale error.
// The caller applies exp(u) - the window's scale, nothing else (the back-end refines the rest).
// Fixed memory: buffers sized at construction (the reduced system is at most kMaxKeyframes poses).
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "mcslam/backend/robust_loss.hpp"
#include "mcslam/backend/schur_accumulator.hpp"
#include "mcslam/odometry/map.hpp"
#include "mcslam/odometry/rig_state.hpp"

namespace mcslam {

struct ScaleEstimate {
  bool ok = false;                   // a minimum inside the searched range, with a finite curvature
  double scale = 1;                  // multiply positions about `center` by this
  double relative_sigma = INFINITY;  // sigma(s) / s
  Vec3 center = Vec3::Zero();        // position of the window's oldest keyframe
  int oldest_slot = -1;              // its map slot
  uint64_t oldest_frame = 0;         // its frame
  int keyframes = 0;
  int64_t oldest_id = -1, newest_id = -1;  // the window's keyframe ids
  int landmarks = 0;
  int observations = 0;
  // chi2 per degree of freedom at the minimum, in the octaves' pixel sigmas: how far the window's residuals are
  // from the noise the sigma assumes (the sigma is inflated by it when above 1).
  double reduced_chi2 = 0;
};

class ScaleEstimator {
 public:
  // max_observations: observations of window landmarks by window keyframes (window * cameras * features);
  // max_keyframes: the map's keyframe capacity. All scratch is allocated here: no estimate allocates.
  ScaleEstimator(const Rig& rig, int max_landmarks, int max_observations, int max_keyframes, float octave_scale_factor,
                 int levels);
  // Takes the current extrinsics by value (the next estimate uses them); allocates nothing.
  void follow(const RigState& state) { rig_ = state.rig(); }

  // Uses the map's newest live keyframes (up to kMaxKeyframes) and the landmarks that kMinLandmarkKeyframes of
  // them observe. `max_ratio` bounds the coarse search: s in [1 / max_ratio, max_ratio]; at most 1, the
  // refinement starts from the map as it is.
  ScaleEstimate estimate(const Map& map, double max_ratio);
  // estimate() in two halves, so that the second can run on another thread while the map changes. prepare()
  // copies the window out of the map (false: too few keyframes or landmarks, `out` says how many); solve() works
  // on the copy only and completes `out`. With `unit_known` the refinement starts from the map's unit, and the
  // coarse search runs only when it finds no minimum within one profile factor of it.
  bool prepare(const Map& map, ScaleEstimate& out);
  void solve(double max_ratio, bool unit_known, ScaleEstimate& out);
  static constexpr int kMaxKeyframes = 16;
  static constexpr int kMinLandmarkKeyframes = 3;
  // The profile's landmarks: an even sample of the window's, at most this many.
  static constexpr int kProfileLandmarks = 400;

 private:
  static constexpr int kMaxDim = 6 * (kMaxKeyframes - 1);
  using Reduced = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxDim, kMaxDim>;
  using ReducedVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxDim, 1>;
  struct Obs {
    int16_t kf;  // index into kf_T_
    int16_t cam;
    Vec2 uv;
    double inv_sigma;
  };
  class Problem;                                          // the Levenberg-Marquardt problem of refine()
  bool selectWindow(const Map& map, ScaleEstimate& out);  // keyframes: kf_T_, oldest_, out's window fields
  // eligible_, lm_p_, lm_first_, obs_, np_; false when the map holds more eligible landmarks than it was sized for.
  bool collectLandmarks(const Map& map, const Vec3& center);
  // Appends the first `eligible` landmarks of eligible_ with their window observations: every stride-th of them
  // (the profile's share), or the others.
  void appendLandmarks(const Map& map, const Vec3& center, int eligible, int stride, bool profile_share);
  int windowViews(const Landmark& L) const;  // window keyframes that observe L
  bool profileScale(double max_ratio);       // the coarse search
  double cost();  // robust cost of the window as it is, every landmark at its best position for the poses
  // Robust cost of landmark l at p, keyframes at kf_T_; p is refined first (two Gauss-Newton steps).
  double landmarkCost(int l, Vec3& p);
  // Up to `steps` Levenberg-Marquardt steps from kf_T_ / lm_p_ (only steps that lower the cost are taken).
  // c: the cost at the end; u_step: how much the last step taken moved u (first order). False when the
  // system is not finite.
  bool refine(int steps, double& c, double& u_step, int* taken = nullptr);
  // The refinement from the map's unit when that unit is known: false (the window restored) when it took no step
  // or moved the scale past one profile factor, a minimum outside the basin the unit is known to be in.
  bool refineNearUnit(double& c, double& u_step);
  void scaleWindow(double s);  // keyframe positions and landmarks times s, about the centre
  void saveWindow(std::vector<SE3>& kf, std::vector<Vec3>& lm) const;
  void restoreWindow(const std::vector<SE3>& kf, const std::vector<Vec3>& lm);
  // The reduced (Schur-complemented) system of the window at kf_T_ / lm_p_ (landmarks re-triangulated first),
  // and the variance of u it implies. False when not finite.
  bool reducedSystem(double& chi2, int& residuals);
  bool dampedStep(double mu, ReducedVec& step);  // solves (S + mu D) step = -b (backend::dampedMatrix)
  double scaleOfPoses() const;                   // summed distances of the keyframes from the oldest (the centre)
  // Block of window keyframe w in the reduced pose system (-1: the oldest, held).
  int freeIndex(int w) const { return w == oldest_ ? -1 : (w < oldest_ ? w : w - 1); }

  Rig rig_;  // a copy: follow() moves its extrinsics
  backend::RobustLoss loss_;
  std::vector<double> octave_sigma_;
  std::vector<SE3> T_c_b_;               // per camera, from the rig at prepare() (its extrinsics may follow
                                         // the back-end's)
  std::vector<SE3> kf_T_;                // per window keyframe: T_w_b, translation relative to the centre
  std::vector<SE3> kf_before_;           // kf_T_ before a refinement step
  std::vector<SE3> kf_start_, kf_best_;  // the window as the map has it, and the profile's best fit
  std::vector<Vec3> lm_start_, lm_best_;
  int oldest_ = 0;                   // window index of the oldest keyframe (held)
  backend::SchurAccumulator schur_;  // eliminates the landmarks from the reduced pose system
  Reduced S_, damped_;
  ReducedVec b_, g_;
  double scale_variance_ = 0;  // g^T S^-1 g of the last reduced system
  bool hold_scale_ = false;    // reducedSystem() keeps u at held_u_ (the profile's fits)
  double held_u_ = 0;
  std::vector<int> kf_slot_of_;  // map keyframe slot -> window index (-1)
  std::vector<int> kf_order_;    // window index -> map keyframe slot (the first nk_), then the other live ones
  std::vector<int> eligible_;    // map slots of the landmarks seen from enough window keyframes, in pool order
  std::vector<Vec3> lm_p_;       // per landmark: position relative to the centre
  std::vector<int> lm_first_;    // per landmark: first observation (lm_first_[l + 1] ends it)
  std::vector<Obs> obs_;
  int nk_ = 0, nl_ = 0, no_ = 0;
  int np_ = 0;  // the first np_ landmarks are the profile's
};

// The window estimates, combined into the map's log-scale error. Windows that share keyframes are not
// independent, and of two that overlap in a turn the later usually holds more of it (its sigma falls from tens
// of percent to a few as the turn enters the window): of overlapping windows only the most certain counts
// (pending); it is fused with the earlier ones (committed) once a window sharing no keyframe with it arrives
// (counting every window by its share of new keyframes would weigh the windows before a turn, which saw little
// of it, like the turn's own). An estimate that disagrees with the combined one by more than 3 sigma
// is dropped; when several in a row disagree, the map's scale has drifted (a straight stretch hides it) and the
// combination restarts from the latest. Windows of one turn also share their scene and the map's history:
// rotationSpan() says over how much rotation of the rig (radians travelled, `rotation` of add()) the combined
// estimates were gathered. With a drift set (once the odometry declared the scale), what is known of the unit
// fades with the keyframes since: the estimates of one turn then correct the drift of the straight before it;
// where a window more certain than the committed part contradicts it beyond both sigmas, the unit jumped rather
// than drifted, and the committed part is held only as certain as the disagreement allows.
// (Before that the combination tests whether windows of different turns agree on one unit; drift there shows
// as disagreement, and the combination restarts.)
class ScaleFilter {
 public:
  void reset() {
    committed_ = pending_ = Part{};
    pending_newest_ = last_newest_ = -1;
    drift_variance_ = 0;
    rejected_ = 0;
    first_rotation_ = last_rotation_ = 0;
  }
  // False when the estimate was dropped as an outlier. The window spans keyframe ids [oldest_id, newest_id];
  // `rotation`: the rig's rotation travelled so far.
  bool add(double log_scale, double sigma, int64_t oldest_id, int64_t newest_id, double rotation);
  double correction() const { return fuse(committed_, pending_).x; }  // log of the factor the map needs
  double sigma() const { return info() > 0 ? 1.0 / std::sqrt(info()) : INFINITY; }
  // The same with the drift since the last window added, up to keyframe `newest_id` (on a straight no window is
  // added, and the unit drifts most there).
  double sigmaAt(int64_t newest_id) const {
    if (!(info() > 0)) return INFINITY;
    const double keyframes = last_newest_ >= 0 && newest_id > last_newest_ ? double(newest_id - last_newest_) : 0.0;
    return std::sqrt(1.0 / info() + drift_variance_ * keyframes);
  }
  double rotationSpan() const { return last_rotation_ - first_rotation_; }
  // From now on the unit random-walks by this relative sigma per keyframe (0: it holds).
  void setDrift(double sigma_per_keyframe) { drift_variance_ = sigma_per_keyframe * sigma_per_keyframe; }
  // The map took the correction: the estimates stay, relative to its new unit.
  void applied() {
    const double x = correction();
    committed_.x -= x;
    pending_.x -= x;
  }

 private:
  struct Part {
    double x = 0, info = 0;  // log-scale and its information (0: none)
  };
  static Part fuse(const Part& a, const Part& b) {  // information-weighted; none from either: none
    const double info = a.info + b.info;
    return info > 0 ? Part{(a.x * a.info + b.x * b.info) / info, info} : Part{};
  }
  double info() const { return committed_.info + pending_.info; }
  static constexpr int kRestartAfter = 3;
  Part committed_, pending_;
  int64_t pending_newest_ = -1;  // newest keyframe id of the pending window
  int64_t last_newest_ = -1;     // newest keyframe id of any window added
  double drift_variance_ = 0;    // per keyframe
  int rejected_ = 0;
  int64_t first_rejected_newest_ = -1;  // newest keyframe id of the first window of the rejected run
  double first_rotation_ = 0, last_rotation_ = 0;
};

}  // namespace mcslam
