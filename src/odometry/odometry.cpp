#include "mcslam/odometry/odometry.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <spdlog/spdlog.h>

#include "extrinsic_check.hpp"
#include "mcslam/odometry/initialization_attempt.hpp"
#include "mcslam/odometry/initializer.hpp"
#include "mcslam/odometry/local_mapper.hpp"
#include "mcslam/odometry/scale_supervisor.hpp"
#include "mcslam/odometry/temporal_triangulator.hpp"
#include "mcslam/odometry/tracker.hpp"
#include "mcslam/odometry/window_bridge.hpp"

namespace mcslam {

namespace {

using Clock = std::chrono::steady_clock;
// The unit sigma of a roughly metric map: its points were seen at under metric_disparity_px, where a few tenths of
// a pixel of calibration error are several percent of depth, and at a pixel tens of percent. Above
// PlaceMemory's bar for uncertain units (10%): its places are measured again as an unscaled map's are.
constexpr double kRoughlyMetricUnitSigma = 0.25;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

}  // namespace

Odometry::Odometry(const Rig& rig, const OdometryOptions& options, int max_features_per_camera)
    : options_(options), map_(rig, max_features_per_camera, options.max_keyframes, options.max_landmarks) {
  const int cams = rig.size();
  tracker_ = std::make_unique<Tracker>(rig, options_, max_features_per_camera);
  initializer_ = std::make_unique<Initializer>(rig, options_, max_features_per_camera);
  attempt_ =
      std::make_unique<InitializationAttempt>(*initializer_, cams, max_features_per_camera, options.backend_thread);
  mapper_ = std::make_unique<LocalMapper>(options_);
  bridge_ = std::make_unique<WindowBridge>(rig, options_, max_features_per_camera);
  triangulator_ = std::make_unique<TemporalTriangulator>(rig, options_, max_features_per_camera);
  if (options.backend && options.refine_extrinsics && cams > 1) {
    extrinsic_check_ = std::make_unique<ExtrinsicCheck>(rig, options_, max_features_per_camera);
  }
  scale_ = std::make_unique<ScaleSupervisor>(rig, options_, max_features_per_camera);
  mapping_.odometry = this;
}

// A keyframe's mapping in flight uses the map, the mapper and the triangulator.
Odometry::~Odometry() { bridge_->wait(); }

Rig Odometry::refinedRig() const { return bridge_->refinedRig(); }

const RigState& Odometry::rigState() const { return bridge_->rigState(); }

double Odometry::unitSigma() const {
  if (bridge_->rigState().scale() == ScaleStatus::Uncertain) return kRoughlyMetricUnitSigma;
  const int newest = map_.newestKeyframe();
  return scale_->unitSigma(newest >= 0 ? map_.keyframe(newest).id : -1);
}

uint64_t Odometry::backendThreadAllocations() const {
  return bridge_->backendThreadAllocations() + scale_->threadAllocations() + attempt_->threadAllocations();
}

void Odometry::resetMap() {
  pending_keyframe_ = -1;  // its window goes with the map
  mapping_due_ = false;
  clearMap();
  attempt_->cancel();  // an attempt in flight uses the initializer
  initializer_->reset();
  if (extrinsic_check_) extrinsic_check_->reset();
  tracker_->reset();
}

void Odometry::clearMap() {
  bridge_->reset();  // first: it waits for a job that may still write the map
  map_.clear();
  mapper_->reset();
}

void Odometry::process(const FrameFeatures& frame, uint64_t frame_index, PoseEstimate& out) {
  processFrame(frame, frame_index, out);
  // As of the end of the frame: a scale that converged in it already rescaled this pose.
  publishUnit(out);
}

void Odometry::publishUnit(PoseEstimate& out) const {
  out.metric = bridge_->rigState().metric();
  out.roughly_metric = bridge_->rigState().scale() == ScaleStatus::Uncertain;
}

void Odometry::processFrame(const FrameFeatures& frame, uint64_t frame_index, PoseEstimate& out) {
  timing_ = OdometryTiming{};
  ++stats_.frames;
  out = PoseEstimate{};
  out.t = frame.t;
  out.sequence = frame_index;
  frame_index_ = frame_index;
  if (!loss_clock_.frame(frame.t)) noteStampNotIncreasing(frame, frame_index);
  settled_count_ = 0;
  rescale_count_ = 0;
  applyDueSolve();
  tracker_->follow(bridge_->rigState());  // a frame boundary: tracking takes the rig state as it is now
  auto start = Clock::now();
  const double flushed_ms = timing_.mapping_ms + timing_.backend_ms;

  if (!initialized_) {
    const bool started_before = initialize(frame, frame_index, out);
    timing_.tracking_ms = msSince(start) - (timing_.mapping_ms + timing_.backend_ms - flushed_ms);
    if (!started_before) return;
    // The map started at the last frame (its attempt's result): this frame is tracked on it.
    tracker_->follow(bridge_->rigState());
    start = Clock::now();
  }

  if (lost_frames_ > options_.max_lost_frames) {
    // A loss this long leaves the motion model too far from the truth for tracking to be trusted: only place
    // memory's relocalization (verified against the place map) brings the frame back, until the timeout starts a
    // new map.
    lose(frame_index, 0, out);
    timing_.tracking_ms += msSince(start);
    return;
  }
  SE3 T_w_b;
  int inliers = 0;
  map_.refreshLiveList();  // tracking and the extrinsic check read the live list
  if (!tracker_->track(map_, frame, frame_index, T_w_b, inliers)) {
    lose(frame_index, inliers, out);
    timing_.tracking_ms += msSince(start);
    return;
  }
  lost_frames_ = 0;
  ++stats_.tracking;
  stats_.recoveries = tracker_->recoveries();
  if (extrinsic_check_ && !bridge_->solving()) {
    // No solve runs now: the back-end's estimate may be replaced.
    SE3 T_b_c;
    const int cam = extrinsic_check_->check(map_, tracker_->search(), bridge_->rigState().rig(), frame,
                                            tracker_->matches(), T_w_b, T_b_c);
    if (cam >= 0) {
      bridge_->reestimateExtrinsic(cam, T_b_c);
      ++stats_.extrinsic_reestimations;
    }
  }
  tracker_->advance(T_w_b);
  timing_.tracking_ms += msSince(start);

  if (tracker_->needKeyframe(map_, T_w_b, inliers, frame_index)) {
    if (pending_keyframe_ >= 0) {
      flush();  // the new keyframe joins the solved map, at this frame's pose moved with it
      T_w_b = tracker_->pose();
    }
    makeKeyframe(frame, frame_index, T_w_b, inliers, out);
  }
  tracker_->rememberTracked(map_, frame, frame_index);
  if (!out.is_keyframe) spdlog::trace("odometry: frame {}: {} inliers", frame_index, inliers);
  out.T_w_b = tracker_->pose();
  out.state = TrackingState::Tracking;
  out.valid = true;
  out.quality = tracker_->quality(inliers);
}

// Logged at the 1st, 2nd, 4th, 8th... occurrence: a camera whose clock is stuck would otherwise log every frame.
void Odometry::noteStampNotIncreasing(const FrameFeatures& frame, uint64_t frame_index) {
  const uint64_t n = ++stats_.stamps_not_increasing;
  if ((n & (n - 1)) != 0) return;
  spdlog::warn(
      "odometry: frame {} is stamped {:.6f} s, not after the frame before ({} such frames so far: a camera clock "
      "stepped back, or a frame delivered twice); the time lost is counted without them",
      frame_index, toSeconds(frame.t), n);
}

void Odometry::lose(uint64_t frame_index, int inliers, PoseEstimate& out) {
  ++stats_.lost;
  if (lost_frames_++ == 0) loss_clock_.startLoss();
  spdlog::trace("odometry: frame {}: lost ({} inliers; {} frames in a row)", frame_index, inliers, lost_frames_);
  // Carry on with the motion model so the trajectory stays continuous, and rebuild the map from there when the
  // loss lasts.
  out.T_w_b = tracker_->coast();
  out.state = TrackingState::Lost;
  out.valid = true;
  if (lost_frames_ > options_.max_lost_frames && loss_clock_.lostSeconds() >= options_.lost_timeout_s) {
    anchor_ = tracker_->pose();
    initialized_ = false;
    resetMap();
  }
}

void Odometry::makeKeyframe(const FrameFeatures& frame, uint64_t frame_index, const SE3& T_w_b, int inliers,
                            PoseEstimate& out) {
  const auto map_start = Clock::now();
  const int slot = mapper_->insertKeyframe(map_, *bridge_, bridge_->rigState().rig(), frame, &tracker_->matches(),
                                           T_w_b, frame_index);
  if (slot < 0) return;
  // Its near points are in the map now; its new points across time and its solve follow the metric rules.
  if (bridge_->rigState().scale() == ScaleStatus::Uncertain && seesMetricPoints(frame))
    unitBecomesMetric(frame, frame_index);
  if (mappingDeferrable()) {
    deferMapping(slot);
    spdlog::trace("odometry: frame {}: keyframe, {} inliers, new landmarks on the back-end thread", frame_index,
                  inliers);
    timing_.mapping_ms += msSince(map_start);
  } else {
    mapNow(slot, frame_index, inliers, map_start);
  }
  tracker_->keyframeMade(frame_index, T_w_b);
  ++stats_.keyframes;
  out.is_keyframe = true;
  if (pending_keyframe_ < 0) {
    finishKeyframe(slot);  // no back-end: cull now
  } else if (!options_.backend_thread) {
    flush();  // the solve ran inline: apply it now, as before the back-end had a thread
  }
}

void Odometry::unitBecomesMetric(const FrameFeatures& frame, uint64_t frame_index) {
  // No solve is in flight here (a keyframe's flushes the one before it): the window may let the unit go, and the
  // metric points this keyframe brings pull it to the metre as a metric start's do.
  bridge_->setScaleStatus(ScaleStatus::Metric);
  bridge_->holdScale(false);
  restUnitOnWindow(false);
  tracker_->unitLeavesWindow();
  stats_.scale_converged_frame = static_cast<int64_t>(frame_index);
  spdlog::info(
      "odometry: frame {}: the map's unit is the metre from now on ({} multi-view points at {} px of "
      "disparity or more)",
      frame_index, metricMultiView(frame), options_.metric_disparity_px);
}

void Odometry::mapNow(int slot, uint64_t frame_index, int inliers, Clock::time_point map_start) {
  const int created = triangulateNew(slot);
  spdlog::trace("odometry: frame {}: keyframe, {} inliers, {} new landmarks", frame_index, inliers, created);
  timing_.mapping_ms += msSince(map_start);
  const auto be_start = Clock::now();
  if (bridge_->beginSolve(map_, slot)) {
    pending_keyframe_ = slot;
    pending_frames_ = 0;
  }
  timing_.backend_ms += msSince(be_start);
}

// Where the next frame waits for this keyframe's solve anyway, and a thread can take the mapping.
bool Odometry::mappingDeferrable() const {
  return options_.defer_keyframe_mapping && options_.backend && options_.backend_thread && apply_after_frames_ == 1;
}

void Odometry::deferMapping(int slot) {
  mapping_due_ = true;
  pending_keyframe_ = slot;
  pending_frames_ = 0;
}

void Odometry::startDeferredMapping() {
  if (!mapping_due_) return;
  mapping_due_ = false;
  mapping_.slot = pending_keyframe_;
  bridge_->beginSolveAfter(map_, mapping_.slot, mapping_);
}

void Odometry::KeyframeMapping::run() {
  const int created = odometry->triangulateNew(slot);
  spdlog::trace("odometry: keyframe {}: {} new landmarks (back-end thread)", odometry->map_.keyframe(slot).id, created);
}

int Odometry::triangulateNew(int slot) {
  const Rig& rig = bridge_->rigState().rig();
  const int created = triangulator_->triangulate(map_, rig, slot);
  mapper_->updateAppearance(map_, rig, triangulator_->created(), !triangulator_->mapFull());
  return created;
}

void Odometry::flush() {
  startDeferredMapping();
  if (pending_keyframe_ < 0) return;
  const int slot = pending_keyframe_;
  pending_keyframe_ = -1;
  const auto start = Clock::now();
  const bool applied = bridge_->finishSolve(map_);  // waits for the solve when it runs on the back-end thread
  if (applied && options_.refine_extrinsics) {
    // Tracking continues with the extrinsics the back-end refined, as it does with its poses and points.
    bridge_->adoptSolvedExtrinsics();
  }
  timing_.backend_ms += msSince(start);
  finishKeyframe(slot);  // its culling counts as mapping
}

void Odometry::applyDueSolve() {
  if (pending_keyframe_ < 0) return;
  ++pending_frames_;
  if (pending_frames_ >= apply_after_frames_ || !initialized_ || lost_frames_ > 0) flush();
}

void Odometry::finishKeyframe(int slot) {
  const auto cull_start = Clock::now();
  noteSettled(slot);
  mapper_->cull(map_, *bridge_, slot, tracker_->landmarkTracks());
  // The back-end moved the keyframe's pose: tracking continues from there.
  tracker_->keyframeSettled(map_, slot);
  estimateScale();
  timing_.mapping_ms += msSince(cull_start);
}

void Odometry::estimateScale() {
  const ScaleSupervisor::Rescale r = scale_->takeEstimate(map_, bridge_->rigState(), frame_index_, stats_);
  if (r.apply) {
    // The whole live map, the window and the motion model take the new unit at once.
    bridge_->rescale(map_, r.s, r.center);
    tracker_->rescale(r.s, r.center);
    if (rescale_count_ < static_cast<int>(rescales_.size()))
      rescales_[static_cast<std::size_t>(rescale_count_++)] = {r.s, r.center, r.from_frame};
    if (r.converged) bridge_->setScaleStatus(ScaleStatus::Metric);
  }
  scale_->startEstimate(map_, bridge_->rigState(), tracker_->rotationTravelled(), frame_index_);
}

bool Odometry::initialize(const FrameFeatures& frame, uint64_t frame_index, PoseEstimate& out) {
  out.T_w_b = anchor_;
  out.state = TrackingState::NotInitialized;
  last_init_ = InitializationSpan{};
  if (attempt_->pending() && startFromAttempt()) return true;
  initializer_->follow(bridge_->rigState());  // a frame boundary, and no attempt in flight
  if (initializer_->oneFrameReady(frame)) {
    const int kf_new = initializeFromOneFrame(frame, frame_index);
    if (kf_new >= 0) {
      startMap(kf_new, frame_index, startScale(frame, /*overlap=*/true));
      publishStart(out);
      return false;
    }
  } else {
    attempt_->submit(frame, frame_index);  // taken at the next frame
  }
  ++stats_.not_initialized;
  return false;
}

bool Odometry::startFromAttempt() {
  SE3 T_ref_cur;
  if (attempt_->collect(T_ref_cur) != Initializer::TwoFrame::Ready) return false;
  const uint64_t start_index = attempt_->frameIndex();
  const int kf_new = initializeFromTwoFrames(attempt_->frame(), start_index, T_ref_cur);
  if (kf_new < 0) return false;
  startMap(kf_new, start_index, startScale(attempt_->frame(), initializer_->lastMetric()));
  last_init_.start = static_cast<int64_t>(start_index);
  last_init_.T_w_start = tracker_->pose();
  PoseEstimate unit;
  publishUnit(unit);
  last_init_.metric = unit.metric;
  last_init_.roughly_metric = unit.roughly_metric;
  return true;
}

int Odometry::initializeFromOneFrame(const FrameFeatures& frame, uint64_t frame_index) {
  // Enough metric multi-view features: the map starts from this frame alone.
  resetMap();
  const int kf_new =
      mapper_->insertKeyframe(map_, *bridge_, bridge_->rigState().rig(), frame, nullptr, anchor_, frame_index);
  if (kf_new >= 0) bridge_->optimize(map_, kf_new);
  return kf_new;
}

int Odometry::initializeFromTwoFrames(const FrameFeatures& frame, uint64_t frame_index, const SE3& T_ref_cur) {
  const auto map_start = Clock::now();
  const FrameFeatures& ref = initializer_->reference();
  const uint64_t ref_index = initializer_->referenceIndex();
  clearMap();
  const Rig& rig = bridge_->rigState().rig();
  const int kf_ref = mapper_->insertKeyframe(map_, *bridge_, rig, ref, nullptr, anchor_, ref_index);
  const int kf_new =
      kf_ref >= 0 ? mapper_->insertKeyframe(map_, *bridge_, rig, frame, nullptr, anchor_ * T_ref_cur, frame_index) : -1;
  const int created = kf_new >= 0 ? triangulateNew(kf_new) : 0;
  timing_.mapping_ms = msSince(map_start);
  if (created < options_.init_min_matches / 2) {
    // Too few points survive triangulation: keep the reference and wait for more motion.
    clearMap();
    return -1;
  }
  const auto be_start = Clock::now();
  bridge_->optimize(map_, kf_ref);
  bridge_->optimize(map_, kf_new);
  timing_.backend_ms = msSince(be_start);
  last_init_.reference = static_cast<int64_t>(ref_index);
  last_init_.T_w_reference = map_.keyframe(kf_ref).T_w_b;
  return kf_new;
}

ScaleStatus Odometry::startScale(const FrameFeatures& frame, bool overlap) const {
  if (bridge_->rigState().cameras() == 1) return ScaleStatus::Monocular;
  if (!overlap) return ScaleStatus::Unscaled;
  return seesMetricPoints(frame) ? ScaleStatus::Metric : ScaleStatus::Uncertain;
}

bool Odometry::seesMetricPoints(const FrameFeatures& frame) const {
  return metricMultiView(frame) >= options_.init_min_multiview;
}

int Odometry::metricMultiView(const FrameFeatures& frame) const {
  return Initializer::metricMultiView(frame, bridge_->rigState().rig(), options_.landmark_max_depth_sigma,
                                      options_.metric_disparity_px);
}

void Odometry::startMap(int kf_new, uint64_t frame_index, ScaleStatus scale, bool new_map) {
  const bool unit_on_window = scale != ScaleStatus::Metric;
  initializer_->reset();
  initialized_ = true;
  bridge_->setScaleStatus(scale);
  // A map that starts up to scale, or whose unit is uncertain, keeps its unit (the window holds it:
  // OdometryOptions::hold_window_scale) and only the scale supervisor's rescales change it: a free window lets the
  // scale random-walk wherever nothing constrains it (no turn; cross-camera points at a pixel of disparity).
  // resetMap() lets it go.
  if (scale == ScaleStatus::Unscaled || scale == ScaleStatus::Uncertain) bridge_->holdScale(true);
  restUnitOnWindow(unit_on_window);
  scale_->start(scale == ScaleStatus::Unscaled);
  if (new_map) ++stats_.initializations;  // a relocalization continues the map it found
  ++stats_.keyframes;
  tracker_->startFrom(map_, kf_new, frame_index, unit_on_window);  // from the landmarks of the new keyframe
  lost_frames_ = 0;
  for (int k = 0; k < map_.keyframeCapacity(); ++k)
    if (map_.keyframe(k).alive) noteSettled(k);  // the keyframes of the start are final: solved once
}

void Odometry::restUnitOnWindow(bool on_window) {
  triangulator_->setSceneReferencedPoints(on_window);
  // A map whose unit rests on its window (one camera, no overlap before the scale is found, roughly metric) tracks
  // on solved maps only: a frame tracked on the map before its solve keeps the unit that solve corrects.
  apply_after_frames_ = on_window ? 1 : options_.backend_apply_after_frames;
}

void Odometry::publishStart(PoseEstimate& out) {
  ++stats_.tracking;
  out.T_w_b = tracker_->pose();
  out.state = TrackingState::Tracking;
  out.valid = true;
  out.is_keyframe = true;
  out.quality = 1.0f;
}

void Odometry::noteSettled(int slot) {
  if (settled_count_ < static_cast<int>(settled_.size())) settled_[static_cast<std::size_t>(settled_count_++)] = slot;
}

void Odometry::relocalize(const FrameFeatures& frame, uint64_t frame_index, const SE3& T_w_b,
                          std::span<const MapSeed> seeds, PoseEstimate& out) {
  const ScaleStatus status = bridge_->rigState().scale();
  settled_count_ = 0;  // the caller took the last frame's before it asked
  resetMap();
  anchor_ = T_w_b;
  const int kf =
      mapper_->insertSeededKeyframe(map_, *bridge_, bridge_->rigState().rig(), frame, seeds, T_w_b, frame_index);
  if (kf < 0) return;
  bridge_->optimize(map_, kf);
  ++stats_.relocalizations;
  out = PoseEstimate{};
  out.t = frame.t;
  out.sequence = frame_index;
  startMap(kf, frame_index, status, /*new_map=*/false);
  publishStart(out);
  publishUnit(out);  // after process(): the record it made is replaced
}

}  // namespace mcslam
