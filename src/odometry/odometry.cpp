#include "mcslam/odometry/odometry.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <spdlog/spdlog.h>

#include "extrinsic_check.hpp"
#include "mcslam/odometry/initializer.hpp"
#include "mcslam/odometry/local_mapper.hpp"
#include "mcslam/odometry/scale_estimator.hpp"
#include "mcslam/odometry/tracker.hpp"

namespace mcslam {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// Frames in a row that may fail before the map is dropped and built again.
constexpr int kMaxLostFrames = 5;

}  // namespace

Odometry::Odometry(const Rig& rig, const OdometryOptions& options, int max_features_per_camera)
    : options_(options),
      capacity_(max_features_per_camera),
      map_(rig, max_features_per_camera, options.max_keyframes, options.max_landmarks) {
  const int cams = rig.size();
  tracker_ = std::make_unique<Tracker>(rig, options_, max_features_per_camera);
  initializer_ = std::make_unique<Initializer>(rig, options_, max_features_per_camera);
  mapper_ = std::make_unique<LocalMapper>(rig, options_, map_, max_features_per_camera);
  if (options.backend && options.refine_extrinsics && cams > 1) {
    extrinsic_check_ = std::make_unique<ExtrinsicCheck>(rig, options_, max_features_per_camera);
  }
  if (cams > 1) {
    const int scale_keyframes = std::min(map_.keyframeCapacity(), ScaleEstimator::kMaxKeyframes);
    const int window_obs = scale_keyframes * cams * max_features_per_camera;
    scale_estimator_ = std::make_unique<ScaleEstimator>(rig, std::min(options.max_landmarks, window_obs), window_obs,
                                                        map_.keyframeCapacity(), options.scale_factor, options.levels);
    scale_filter_ = std::make_unique<ScaleFilter>();
  }
}

Odometry::~Odometry() = default;

Rig Odometry::refinedRig() const { return mapper_->refinedRig(); }

const RigState& Odometry::rigState() const { return mapper_->rigState(); }

uint64_t Odometry::backendThreadAllocations() const { return mapper_->backendThreadAllocations(); }

void Odometry::resetMap() {
  pending_keyframe_ = -1;  // its window goes with the map
  map_.clear();
  mapper_->reset();
  initializer_->reset();
  if (extrinsic_check_) extrinsic_check_->reset();
  tracker_->reset();
}

void Odometry::process(const FrameFeatures& frame, uint64_t frame_index, PoseEstimate& out) {
  processFrame(frame, frame_index, out);
  // As of the end of the frame: a scale that converged in it already rescaled this pose.
  out.metric = mapper_->rigState().metric();
}

void Odometry::processFrame(const FrameFeatures& frame, uint64_t frame_index, PoseEstimate& out) {
  timing_ = OdometryTiming{};
  ++stats_.frames;
  out = PoseEstimate{};
  out.t = frame.t;
  out.sequence = frame_index;
  frame_index_ = frame_index;
  flush();  // the previous keyframe's solve, before this frame reads the map
  tracker_->follow(mapper_->rigState());  // a frame boundary: tracking takes the rig state as it is now
  const auto start = Clock::now();
  const double flushed_ms = timing_.mapping_ms + timing_.backend_ms;

  if (!initialized_) {
    initialize(frame, frame_index, out);
    timing_.tracking_ms = msSince(start) - (timing_.mapping_ms + timing_.backend_ms - flushed_ms);
    return;
  }

  SE3 T_w_b;
  int inliers = 0;
  map_.refreshLiveList();  // tracking and the extrinsic check read the live list
  if (!tracker_->track(map_, frame, frame_index, T_w_b, inliers)) {
    lose(frame_index, inliers, out);
    timing_.tracking_ms = msSince(start);
    return;
  }
  lost_frames_ = 0;
  ++stats_.tracking;
  stats_.recoveries = tracker_->recoveries();
  if (extrinsic_check_) {
    // No solve runs now (flush() came first): the back-end's estimate may be replaced.
    SE3 T_b_c;
    const int cam = extrinsic_check_->check(map_, tracker_->search(), mapper_->rigState().rig(), frame,
                                            tracker_->matches(), T_w_b, T_b_c);
    if (cam >= 0) {
      mapper_->reestimateExtrinsic(cam, T_b_c);
      ++stats_.extrinsic_reestimations;
    }
  }
  tracker_->advance(T_w_b);
  timing_.tracking_ms = msSince(start);

  if (tracker_->needKeyframe(map_, T_w_b, inliers, frame_index)) makeKeyframe(frame, frame_index, T_w_b, inliers, out);
  tracker_->rememberTracked(map_, frame, frame_index);
  if (!out.is_keyframe) spdlog::trace("odometry: frame {}: {} inliers", frame_index, inliers);
  out.T_w_b = tracker_->pose();
  out.state = TrackingState::Tracking;
  out.valid = true;
  out.quality = tracker_->quality(inliers);
}

void Odometry::lose(uint64_t frame_index, int inliers, PoseEstimate& out) {
  ++stats_.lost;
  ++lost_frames_;
  spdlog::trace("odometry: frame {}: lost ({} inliers; {} frames in a row)", frame_index, inliers, lost_frames_);
  // Carry on with the motion model so the trajectory stays continuous, and rebuild the map from there when the
  // loss lasts.
  out.T_w_b = tracker_->coast();
  out.state = TrackingState::Lost;
  out.valid = true;
  if (lost_frames_ > kMaxLostFrames) {
    anchor_ = tracker_->pose();
    initialized_ = false;
    resetMap();
  }
}

void Odometry::makeKeyframe(const FrameFeatures& frame, uint64_t frame_index, const SE3& T_w_b, int inliers,
                            PoseEstimate& out) {
  const auto map_start = Clock::now();
  const int slot = mapper_->insertKeyframe(frame, &tracker_->matches(), T_w_b, frame_index);
  if (slot < 0) return;
  const int created = mapper_->triangulateWithPrevious(slot);
  spdlog::trace("odometry: frame {}: keyframe, {} inliers, {} new landmarks", frame_index, inliers, created);
  timing_.mapping_ms = msSince(map_start);
  const auto be_start = Clock::now();
  if (mapper_->beginOptimize(slot)) pending_keyframe_ = slot;
  timing_.backend_ms = msSince(be_start);
  tracker_->keyframeMade(frame_index, T_w_b);
  ++stats_.keyframes;
  out.is_keyframe = true;
  if (pending_keyframe_ < 0) {
    finishKeyframe(slot);  // no back-end: cull now
  } else if (!options_.backend_thread) {
    flush();  // the solve ran inline: apply it now, as before the back-end had a thread
  }
}

void Odometry::flush() {
  if (pending_keyframe_ < 0) return;
  const int slot = pending_keyframe_;
  pending_keyframe_ = -1;
  const auto start = Clock::now();
  const bool applied = mapper_->finishOptimize();  // waits for the solve when it runs on the back-end thread
  if (applied && options_.refine_extrinsics) {
    // Tracking continues with the extrinsics the back-end refined, as it does with its poses and points.
    mapper_->adoptSolvedExtrinsics();
  }
  timing_.backend_ms += msSince(start);
  finishKeyframe(slot);  // its culling counts as mapping
}

void Odometry::finishKeyframe(int slot) {
  const auto cull_start = Clock::now();
  mapper_->cull(slot, tracker_->landmarkTracks());
  // The back-end moved the keyframe's pose: tracking continues from there.
  tracker_->keyframeSettled(map_, slot);
  estimateScale();
  timing_.mapping_ms += msSince(cull_start);
}

double Odometry::windowTurn() const {
  const int oldest = map_.oldestWindowKeyframe();
  double turn = 0;
  for (int i = 0; oldest >= 0 && i < map_.keyframeCapacity(); ++i) {
    const Keyframe& k = map_.keyframe(i);
    if (!k.alive || !k.in_backend) continue;
    turn = std::max(turn, rotationAngle(map_.keyframe(oldest).T_w_b.R, k.T_w_b.R));
  }
  return turn;
}

void Odometry::estimateScale() {
  if (!scale_free_start_ || !scale_estimator_) return;
  // At every keyframe, before convergence and after it (the unit drifts between turns). Afterwards too from the
  // profile: a refinement from the map as it is found the map's own unit (a last corner's window said 1.000 +- 4%
  // where the truth wanted 0.874, rendered 10 cm rig).
  // The lever arms tell the scale only while the window turns: a window that turned less than this is not
  // searched (its estimate comes back with a sigma of tens or thousands of percent, after costing the tracking
  // thread most of a frame: a rig whose scale never converges would pay it at every keyframe).
  constexpr double kMinWindowTurnRad = 2.0 * M_PI / 180.0;
  if (windowTurn() < kMinWindowTurnRad) return;
  // The search range: the whole of it while the unit is arbitrary; within a factor 2 once the combined windows
  // know it to 20% or it has converged (the search re-fits the window at every factor it tries: the range is most
  // of its cost).
  constexpr double kKnownSigma = 0.2, kKnownRatio = 2.0;
  const bool scale_converged = mapper_->rigState().scaleConverged();
  const double ratio = scale_converged || scale_filter_->sigma() <= kKnownSigma
                           ? std::min(kKnownRatio, options_.scale_search_ratio)
                           : options_.scale_search_ratio;
  scale_estimator_->follow(mapper_->rigState());
  const ScaleEstimate e = scale_estimator_->estimate(map_, ratio);
  ++stats_.scale_estimates;
  if (!e.ok) return;
  stats_.last_scale = e.scale;
  stats_.last_scale_sigma = e.relative_sigma;
  if (!scale_filter_->add(std::log(e.scale), e.relative_sigma, e.oldest_id, e.newest_id, tracker_->rotationTravelled())) {
    spdlog::debug("odometry: scale at frame {}: window {:.4f} sigma {:.4f} dropped as an outlier", frame_index_, e.scale,
                  e.relative_sigma);
    return;
  }
  const double x = scale_filter_->correction(), sigma = scale_filter_->sigma();
  stats_.combined_scale_sigma = sigma;
  // One line per estimate, for studies against ground truth (mcslam-run --log-level debug).
  spdlog::debug("odometry: scale at frame {}: window {:.4f} sigma {:.4f} ({} keyframes, {} landmarks, chi2/dof "
                "{:.2f}), combined {:.4f} sigma {:.4f} over {:.0f} deg", frame_index_, e.scale, e.relative_sigma,
                e.keyframes, e.landmarks, e.reduced_chi2, std::exp(x), sigma,
                scale_filter_->rotationSpan() * 180.0 / M_PI);
  // A correction 3 sigma away from 1 is applied at any time: before convergence it brings the arbitrary unit near
  // the metric one (the windows' Gauss-Newton then starts in the basin; a unit 8x off left most windows without
  // an estimate), the poses staying flagged unscaled until the combined sigma reaches the bound.
  const bool converges = !scale_converged && sigma <= options_.scale_max_sigma &&
                         scale_filter_->rotationSpan() >= options_.scale_min_rotation_deg * M_PI / 180.0;
  // Once converged the map follows the combined estimate as the unit drifts, whenever it is 2 sigma off (1 sigma:
  // about the same result, 55 rescales in seven runs of the rendered 10 cm rig against 42).
  const double significant = scale_converged ? 2.0 : 3.0;
  if (!converges && !(std::abs(x) > significant * sigma)) return;
  // The whole live map, the window and the motion model take the new unit at once.
  const double s = std::exp(x);
  spdlog::debug("odometry: map rescaled by {:.4f} at frame {}", s, frame_index_);
  mapper_->rescale(s, e.center);
  tracker_->rescale(s, e.center);
  scale_filter_->applied();
  ++stats_.scale_rescales;
  if (converges) {
    mapper_->setScaleStatus(ScaleStatus::Metric);
    scale_filter_->setDrift(options_.scale_drift_per_keyframe);
    stats_.scale_converged_frame = static_cast<int64_t>(frame_index_);
  }
}

void Odometry::initialize(const FrameFeatures& frame, uint64_t frame_index, PoseEstimate& out) {
  out.T_w_b = anchor_;
  out.state = TrackingState::NotInitialized;
  int kf_new = -1;
  last_init_reference_ = -1;
  bool metric = true;
  const int cams = mapper_->rigState().cameras();
  initializer_->follow(mapper_->rigState());
  if (initializer_->oneFrameReady(frame)) {
    // Enough metric multi-view features: the map starts from this frame alone.
    resetMap();
    kf_new = mapper_->insertKeyframe(frame, nullptr, anchor_, frame_index, true);
    if (kf_new >= 0) mapper_->optimize(kf_new);
  } else {
    SE3 T_ref_cur;
    if (initializer_->feed(frame, frame_index, T_ref_cur) == Initializer::TwoFrame::Ready) {
      const auto map_start = Clock::now();
      const FrameFeatures& ref = initializer_->reference();
      const uint64_t ref_index = initializer_->referenceIndex();
      map_.clear();
      mapper_->reset();
      const int kf_ref = mapper_->insertKeyframe(ref, nullptr, anchor_, ref_index, true);
      kf_new = kf_ref >= 0 ? mapper_->insertKeyframe(frame, nullptr, anchor_ * T_ref_cur, frame_index, true) : -1;
      const int created = kf_new >= 0 ? mapper_->triangulateWithPrevious(kf_new) : 0;
      timing_.mapping_ms = msSince(map_start);
      if (created < options_.init_min_matches / 2) {
        // Too few points survive triangulation: keep the reference and wait for more motion.
        map_.clear();
        mapper_->reset();
        kf_new = -1;
      } else {
        const auto be_start = Clock::now();
        mapper_->optimize(kf_ref);
        mapper_->optimize(kf_new);
        timing_.backend_ms = msSince(be_start);
        last_init_reference_ = static_cast<int64_t>(ref_index);
        metric = initializer_->lastMetric() || cams == 1;  // one camera: never metric, nothing to wait for
      }
    }
  }
  if (kf_new < 0) {
    ++stats_.not_initialized;
    return;
  }
  initializer_->reset();
  initialized_ = true;
  mapper_->setScaleStatus(cams == 1 ? ScaleStatus::Monocular : metric ? ScaleStatus::Metric : ScaleStatus::Unscaled);
  scale_free_start_ = !metric;
  // A map that starts up to scale keeps its unit (the window's summed keyframe distances held, or its two oldest
  // keyframes fixed as for one camera: OdometryOptions::hold_window_scale) and only the estimates of
  // estimateScale() change it. A free window random-walked its scale wherever no turn constrained it: the 33 cm
  // rig's map shrank to a tenth on a straight stretch, the 10 cm rig lost track. resetMap() lets it go.
  if (!metric && cams > 1) mapper_->holdScale(true);
  mapper_->setSceneReferencedPoints(!metric || cams == 1);
  if (scale_filter_) scale_filter_->reset();
  ++stats_.initializations;
  ++stats_.keyframes;
  tracker_->startFrom(map_, kf_new, frame_index);  // from the landmarks of the new keyframe
  ++stats_.tracking;
  out.T_w_b = tracker_->pose();
  out.state = TrackingState::Tracking;
  out.valid = true;
  out.is_keyframe = true;
  out.quality = 1.0f;
}

}  // namespace mcslam
