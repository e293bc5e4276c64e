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

namespace mcslam {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// Frames in a row that may fail before the map is dropped and built again.
constexpr int kMaxLostFrames = 5;

AbsolutePoseRansacOptions ransacOptions(const OdometryOptions& o) {
  AbsolutePoseRansacOptions r;
  r.min_inliers = o.min_tracked;
  r.max_iterations = 300;
  return r;
}

PoseRefinementOptions refinementOptions(const OdometryOptions& o) {
  PoseRefinementOptions r;
  r.min_inliers = o.min_tracked;
  return r;
}

}  // namespace

Odometry::Odometry(const Rig& rig, const OdometryOptions& options, int max_features_per_camera)
    : tracking_rig_(rig),
      options_(options),
      capacity_(max_features_per_camera),
      map_(rig, max_features_per_camera, options.max_keyframes, options.max_landmarks),
      search_(rig, max_features_per_camera),
      ransac_(rig, rig.size() * max_features_per_camera, ransacOptions(options)),
      refiner_(rig, rig.size() * max_features_per_camera, refinementOptions(options)) {
  const int cams = rig.size();
  matches_.allocate(cams, max_features_per_camera, options.max_landmarks);
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
  observations_.resize(static_cast<std::size_t>(cams) * max_features_per_camera);
  observation_refs_.resize(observations_.size());
  last_tracked_.resize(options.max_landmarks);
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
  last_tracked_count_ = 0;
  last_coarse_inliers_ = 0;
  have_velocity_ = false;
}

void Odometry::followRig() {
  if (!tracking_rig_.follow(mapper_->rigState())) return;
  for (int c = 0; c < tracking_rig_.cameras(); ++c) {
    ransac_.setExtrinsic(c, tracking_rig_.T_b_c(c));
    refiner_.setExtrinsic(c, tracking_rig_.T_b_c(c));
  }
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
  followRig();
  const auto start = Clock::now();
  const double flushed_ms = timing_.mapping_ms + timing_.backend_ms;

  if (!initialized_) {
    initialize(frame, frame_index, out);
    timing_.tracking_ms = msSince(start) - (timing_.mapping_ms + timing_.backend_ms - flushed_ms);
    return;
  }

  SE3 T_w_b;
  int inliers = 0;
  const TrackResult result = track(frame, frame_index, T_w_b, inliers);
  if (result == TrackResult::Failed) {
    ++stats_.lost;
    ++lost_frames_;
    spdlog::trace("odometry: frame {}: lost ({} inliers; {} frames in a row)", frame_index, inliers, lost_frames_);
    // Carry on with the motion model so the trajectory stays continuous, and rebuild the map from
    // there when the loss lasts.
    T_w_last_ = have_velocity_ ? T_w_last_ * velocity_ : T_w_last_;
    out.T_w_b = T_w_last_;
    out.state = TrackingState::Lost;
    out.valid = true;
    if (lost_frames_ > kMaxLostFrames) {
      anchor_ = T_w_last_;
      initialized_ = false;
      resetMap();
    }
    timing_.tracking_ms = msSince(start);
    return;
  }
  lost_frames_ = 0;
  ++stats_.tracking;
  if (extrinsic_check_) {
    // No solve runs now (flush() came first): the back-end's estimate may be replaced.
    SE3 T_b_c;
    const int cam = extrinsic_check_->check(map_, search_, mapper_->rigState().rig(), frame, matches_, T_w_b, T_b_c);
    if (cam >= 0) {
      mapper_->reestimateExtrinsic(cam, T_b_c);
      ++stats_.extrinsic_reestimations;
    }
  }
  velocity_ = T_w_last_.inverse() * T_w_b;
  have_velocity_ = true;
  rotation_travelled_ += rotationAngle(T_w_last_.R, T_w_b.R);
  T_w_last_ = T_w_b;
  timing_.tracking_ms = msSince(start);

  if (needKeyframe(T_w_b, inliers, frame_index)) {
    const auto map_start = Clock::now();
    const int slot = mapper_->insertKeyframe(frame, &matches_, T_w_b, frame_index);
    if (slot >= 0) {
      const int created = mapper_->triangulateWithPrevious(slot);
      spdlog::trace("odometry: frame {}: keyframe, {} inliers, {} new landmarks", frame_index, inliers, created);
      timing_.mapping_ms = msSince(map_start);
      const auto be_start = Clock::now();
      if (mapper_->beginOptimize(slot)) pending_keyframe_ = slot;
      timing_.backend_ms = msSince(be_start);
      last_keyframe_frame_ = frame_index;
      last_keyframe_pose_ = T_w_b;
      ++stats_.keyframes;
      out.is_keyframe = true;
      if (pending_keyframe_ < 0) {
        finishKeyframe(slot);  // no back-end: cull now
      } else if (!options_.backend_thread) {
        flush();  // the solve ran inline: apply it now, as before the back-end had a thread
      }
    }
  }
  rememberTracked(frame, frame_index);
  if (!out.is_keyframe) spdlog::trace("odometry: frame {}: {} inliers", frame_index, inliers);
  out.T_w_b = T_w_last_;
  out.state = TrackingState::Tracking;
  out.valid = true;
  out.quality = static_cast<float>(std::min(1.0, inliers / std::max(1.0, 0.5 * last_keyframe_tracked_)));
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
  mapper_->cull(slot);
  // The back-end moved the keyframe's pose: continue from there, with the same velocity.
  T_w_last_ = map_.keyframe(slot).T_w_b;
  last_keyframe_pose_ = T_w_last_;
  last_keyframe_tracked_ = countKeyframeLandmarks(slot);
  // Landmarks the back-end or the culling erased are no longer tracked.
  int kept = 0;
  for (int i = 0; i < last_tracked_count_; ++i) {
    if (map_.landmark(last_tracked_[i]).alive) last_tracked_[kept++] = last_tracked_[i];
  }
  last_tracked_count_ = kept;
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
  if (!scale_filter_->add(std::log(e.scale), e.relative_sigma, e.oldest_id, e.newest_id, rotation_travelled_)) {
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
  T_w_last_.t = e.center + s * (T_w_last_.t - e.center);
  last_keyframe_pose_.t = e.center + s * (last_keyframe_pose_.t - e.center);
  velocity_.t *= s;
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
  T_w_last_ = map_.keyframe(kf_new).T_w_b;
  have_velocity_ = false;
  last_keyframe_frame_ = frame_index;
  last_keyframe_pose_ = T_w_last_;
  last_keyframe_tracked_ = countKeyframeLandmarks(kf_new);
  // Track from the landmarks of the new keyframe.
  last_tracked_count_ = 0;
  last_coarse_inliers_ = 0;
  const Keyframe& kf = map_.keyframe(kf_new);
  for (int c = 0; c < kf.features.cameras(); ++c) {
    for (int k = 0; k < kf.features.sets[c].count; ++k) {
      const int lm = kf.landmark_of[c][k];
      if (lm >= 0 && map_.landmark(lm).matched_frame != frame_index) {
        map_.landmark(lm).matched_frame = frame_index;
        last_tracked_[last_tracked_count_++] = lm;
      }
    }
  }
  ++stats_.tracking;
  out.T_w_b = T_w_last_;
  out.state = TrackingState::Tracking;
  out.valid = true;
  out.is_keyframe = true;
  out.quality = 1.0f;
}

int Odometry::countKeyframeLandmarks(int slot) const {
  const Keyframe& kf = map_.keyframe(slot);
  int n = 0;
  for (int c = 0; c < kf.features.cameras(); ++c) {
    for (int k = 0; k < kf.features.sets[c].count; ++k) n += kf.landmark_of[c][k] >= 0 ? 1 : 0;
  }
  return n;
}

Odometry::TrackResult Odometry::track(const FrameFeatures& frame, uint64_t frame_index, SE3& T_w_b, int& inliers) {
  const SE3 predicted = have_velocity_ ? T_w_last_ * velocity_ : T_w_last_;
  search_.prepare(frame);
  ProjectionSearchParams params;
  params.max_hamming = options_.max_hamming;
  params.ratio = options_.ratio;
  params.scale_factor = options_.scale_factor;
  params.levels = options_.levels;

  // Coarse pose, in up to three attempts of growing cost, until one is strong (a fair share of the previous
  // frame's inliers; a weak consensus is often a wrong pose after a jolt the motion model did not predict):
  //   0. the landmarks tracked in the previous frame, around the motion-model prediction;
  //   1. the whole local map with a wide radius (sudden turns, stops);
  //   2. recovery: the newest keyframe's landmarks matched by descriptor alone, any camera, no geometry.
  // The attempt with the most inliers gives the coarse pose.
  const auto strong = [&](int n) {
    return n >= options_.min_tracked && n >= options_.strong_tracking_share * last_coarse_inliers_;
  };
  SE3 coarse = predicted;
  int best_attempt = -1, last_attempt = -1;
  inliers = 0;
  for (int attempt = 0; attempt < 3 && !strong(inliers); ++attempt) {
    matches_.reset(frame);
    last_attempt = attempt;
    int found = 0;
    if (attempt < 2) {
      params.radius_px = options_.track_radius_px * (attempt == 0 ? 1.0 : options_.wide_radius_factor);
      map_.refreshLiveList();
      const int32_t* slots = attempt == 0 ? last_tracked_.data() : map_.liveLandmarkSlots();
      const int n = attempt == 0 ? last_tracked_count_ : map_.liveLandmarkCount();
      found = search_.search(map_, tracking_rig_.rig(), slots, n, predicted, frame, params, matches_, false);
    } else {
      found = searchNewestKeyframeByDescriptor(frame);
    }
    SE3 candidate = predicted;
    const int n = found >= options_.min_matches_for_pose ? poseFromMatches(frame, predicted, true, candidate) : 0;
    spdlog::trace("odometry: frame {}: coarse attempt {}: {} matches, {} inliers", frame_index, attempt, found, n);
    if (n > inliers) {
      inliers = n;
      coarse = candidate;
      best_attempt = attempt;
    }
  }
  if (inliers < options_.min_tracked) return TrackResult::Failed;
  if (best_attempt == 2) ++stats_.recoveries;
  last_coarse_inliers_ = inliers;
  if (best_attempt != last_attempt) {
    // A later attempt replaced the best one's matches: find them again around the coarse pose.
    matches_.reset(frame);
    map_.refreshLiveList();
    params.radius_px = options_.track_radius_px;
    search_.search(map_, tracking_rig_.rig(), map_.liveLandmarkSlots(), map_.liveLandmarkCount(), coarse, frame, params, matches_, false);
  }

  // 3. The local map, projected with the coarse pose into every camera, then the final refinement.
  map_.refreshLiveList();
  params.radius_px = options_.local_map_radius_px;
  search_.search(map_, tracking_rig_.rig(), map_.liveLandmarkSlots(), map_.liveLandmarkCount(), coarse, frame, params, matches_, true);
  const int refined = poseFromMatches(frame, coarse, false, T_w_b);
  if (refined >= options_.min_tracked) {
    inliers = refined;
  } else {
    T_w_b = coarse;
  }
  // Landmarks found in this frame.
  for (int c = 0; c < frame.cameras(); ++c) {
    for (int k = 0; k < frame.sets[c].count; ++k) {
      const int lm = matches_.landmarkOf(c, k);
      if (lm < 0) continue;
      Landmark& l = map_.landmark(lm);
      if (l.matched_frame != frame_index) {
        l.matched_frame = frame_index;
        ++l.found;
      }
    }
  }
  return TrackResult::Ok;
}

int Odometry::searchNewestKeyframeByDescriptor(const FrameFeatures& frame) {
  const int newest = map_.newestKeyframe();
  int n = 0;
  if (newest >= 0) {
    const Keyframe& kf = map_.keyframe(newest);
    for (int c = 0; c < kf.features.cameras(); ++c) {
      for (int k = 0; k < kf.features.sets[c].count; ++k) {
        if (kf.landmark_of[c][k] >= 0) last_tracked_[n++] = kf.landmark_of[c][k];
      }
    }
  }
  last_tracked_count_ = 0;  // the list now holds keyframe landmarks, possibly repeated: not reusable
  return search_.searchByDescriptor(map_, last_tracked_.data(), n, frame, options_.max_hamming, 0.8f, matches_);
}

int Odometry::poseFromMatches(const FrameFeatures& frame, const SE3& guess, bool use_ransac, SE3& T_w_b) {
  int n = 0;
  for (int c = 0; c < frame.cameras(); ++c) {
    for (int k = 0; k < frame.sets[c].count; ++k) {
      const int lm = matches_.landmarkOf(c, k);
      if (lm < 0 || !frame.valid[c][k]) continue;
      const Keypoint& kp = frame.sets[c].keypoints[k];
      PoseObservation& o = observations_[n];
      o.camera = c;
      o.pixel = Vec2(kp.x, kp.y);
      o.ray = bodyRay(tracking_rig_.rig(), c, frame.bearings[c][k]);
      o.point_w = map_.landmark(lm).p_w;
      o.sigma_px = octave_scale_[kp.octave];
      observation_refs_[n] = KeypointRef{static_cast<int16_t>(c), k};
      ++n;
    }
  }
  if (n < options_.min_matches_for_pose) return 0;
  const std::span<const PoseObservation> obs(observations_.data(), n);
  std::span<const uint8_t> mask;
  int inliers = 0;
  if (use_ransac) {
    const AbsolutePoseRansacResult r = ransac_.estimate(obs, &guess);
    if (!r.ok()) return 0;
    T_w_b = r.T_w_b;
    mask = r.inlier_mask;
    inliers = r.num_inliers;
  } else {
    const PoseRefinementResult r = refiner_.refine(obs, guess);
    if (!r.success) return 0;
    T_w_b = r.T_w_b;
    mask = r.inlier_mask;
    inliers = r.num_inliers;
  }
  for (int i = 0; i < n; ++i) {
    if (!mask[i]) matches_.clear(observation_refs_[i].cam, observation_refs_[i].index);
  }
  return inliers;
}

bool Odometry::needKeyframe(const SE3& T_w_b, int inliers, uint64_t frame_index) const {
  if (frame_index - last_keyframe_frame_ >= static_cast<uint64_t>(options_.keyframe_max_interval)) return true;
  if (inliers < options_.keyframe_tracked_ratio * last_keyframe_tracked_) return true;
  const SE3 motion = last_keyframe_pose_.inverse() * T_w_b;
  if (so3Log(motion.R).norm() * 180.0 / M_PI > options_.keyframe_rotation_deg) return true;
  // Translation against the typical depth of what is tracked.
  double depth_sum = 0;
  int depth_n = 0;
  for (int i = 0; i < last_tracked_count_ && depth_n < 200; ++i) {
    depth_sum += (map_.landmark(last_tracked_[i]).p_w - T_w_b.t).norm();
    ++depth_n;
  }
  const double depth = depth_n ? depth_sum / depth_n : 1.0;
  return motion.t.norm() > options_.keyframe_translation_ratio * depth;
}

void Odometry::rememberTracked(const FrameFeatures& frame, uint64_t frame_index) {
  last_tracked_count_ = 0;
  for (int c = 0; c < frame.cameras(); ++c) {
    for (int k = 0; k < frame.sets[c].count; ++k) {
      const int lm = matches_.landmarkOf(c, k);
      if (lm < 0) continue;
      Landmark& l = map_.landmark(lm);
      if (!l.alive || l.listed_frame == frame_index) continue;  // a landmark seen by several cameras: once
      l.listed_frame = frame_index;
      last_tracked_[last_tracked_count_++] = lm;
    }
  }
}

}  // namespace mcslam
