#include "mcslam/places/place_memory.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "mcslam/places/loop_scale.hpp"

namespace mcslam {

PlaceMemory::PlaceMemory(const Rig& rig, const Vocabulary& vocabulary, const PlacesOptions& options,
                         const OdometryOptions& odometry_options, int max_features_per_camera)
    : vocabulary_(vocabulary),
      options_(options),
      map_(options.max_keyframes, options.max_points_per_keyframe),
      database_(vocabulary.wordCount(), options.max_keyframes, options.max_words_per_keyframe),
      words_(rig.size(), max_features_per_camera),
      relocalizer_(rig, options, odometry_options.scale_factor, max_features_per_camera),
      // One camera's maps never have a metric unit: its loops, when it closes them, are similarities.
      loop_closer_(rig, options, odometry_options.scale_factor, max_features_per_camera,
                   rig.size() == 1 && options.monocular_loop_closure),
      seeds_(static_cast<std::size_t>(rig.size() * max_features_per_camera)),
      camera_centers_(rig.cameraCenters()),
      landmark_stamp_(static_cast<std::size_t>(odometry_options.max_landmarks), -1),
      features_per_camera_(max_features_per_camera),
      unrefined_(static_cast<std::size_t>(odometry_options.max_keyframes)),
      file_words_(options.max_words_per_keyframe),
      kept_ids_(2 * static_cast<std::size_t>(options.max_loops)),
      anchored_(PlaceMap::kMaxSegments, 0),
      root_placed_(PlaceMap::kMaxSegments),
      root_anchored_(PlaceMap::kMaxSegments),
      vocabulary_fingerprint_(vocabularyFingerprint(vocabulary)) {
  own_points_.resize(static_cast<std::size_t>(rig.size()) * static_cast<std::size_t>(max_features_per_camera));
  for (int c = 0; c < rig.size(); ++c)
    cameras_.push_back({static_cast<uint32_t>(rig.model(c).width()), static_cast<uint32_t>(rig.model(c).height())});
  file_header_.cameras = cameras_;
}

void PlaceMemory::afterOdometry(const FrameFeatures& frame, uint64_t frame_index, Odometry& odometry,
                                PoseEstimate& out) {
  // The loop detection started on an earlier keyframe reads the map and the database: a frame that may write them
  // takes its result first, waiting if need be; a frame that only tracks takes it once it is ready.
  collectLoopDetection(/*wait=*/!onlyReadsMap(odometry, out));
  takeCorrection(options_.repeatable);
  followSegment(odometry);
  // Before the keyframes settled in this frame join: they are in the new unit already.
  // The lever arms the odometry rescaled its landmarks with.
  if (!odometry.rescales().empty()) odometry.trackingRig().cameraCenters(camera_centers_);
  for (const Odometry::Rescale& r : odometry.rescales()) {
    map_.rescaleSegment(segment_, r.s, r.center, r.from_frame, camera_centers_);
    loop_closer_.followRescale(map_, segment_, r.s, r.from_frame);
  }
  if (!localize_only_) {
    refinePlaces(odometry);  // before a loop of this frame's keyframes starts a correction from their poses
    for (const int32_t slot : odometry.settledKeyframes()) addKeyframe(odometry, slot);
  }
  if (out.state == TrackingState::Tracking && out.valid) {  // the odometry's path, for the drift it can have
    if (have_last_position_) path_ += (out.T_w_b.t - last_position_).norm();
    last_position_ = out.T_w_b.t;
    have_last_position_ = true;
  } else {
    have_last_position_ = false;
  }
  if (out.state != TrackingState::Tracking && map_.size() > 0 && segment_ >= 0) {
    relocalize(frame, frame_index, odometry, out);
  } else if (out.state == TrackingState::Tracking && out.valid && segment_ >= 0 &&
             (!map_.placed(segment_) || (localize_only_ && out.is_keyframe))) {
    place(frame, frame_index, odometry, out.T_w_b);
  }
  if (out.valid && !toWorld(out.T_w_b, out.T_w_b)) {
    out.valid = false;
    out.state = TrackingState::Localizing;
  }
  out.world_revision = world_revision_;
  out.unanchored = out.valid && segment_ >= 0 && !anchored_[static_cast<std::size_t>(segment_)];
}

bool PlaceMemory::toWorld(const SE3& T_o_b, SE3& T_w_b) const {
  if (segment_ < 0) {
    T_w_b = T_o_b;
    return true;
  }
  if (!map_.placed(segment_)) return false;
  T_w_b = map_.toWorld(segment_, T_o_b);
  return true;
}

// A new odometry map (after a loss nothing bridged, or the very first) is a new segment. Its frame continues the
// old one's (the odometry starts it at the pose it coasted to), so it starts with the same T_w_o; a later
// recognition joins it to the map.
void PlaceMemory::followSegment(const Odometry& odometry) {
  if (odometry.stats().initializations == initializations_seen_) return;
  initializations_seen_ = odometry.stats().initializations;
  const SE3 T_w_o = segment_ >= 0 ? map_.segmentPose(segment_) : SE3();
  const double scale = segment_ >= 0 ? map_.segmentScale(segment_) : 1.0;
  // The first map of a run that reuses a saved one is nowhere in it until recognized.
  const bool placed = segment_ >= 0 ? map_.placed(segment_) : !loaded_;
  int32_t s = map_.createSegment(T_w_o, placed, segment_);
  if (s < 0) s = reuseSegment(T_w_o, placed);
  if (s < 0) {
    spdlog::warn("place memory: {} odometry maps with keyframes or loops; the newest keeps the last one's frame",
                 PlaceMap::kMaxSegments);
    return;
  }
  map_.setSegmentScale(s, scale);
  // The run's first map defines the world; a later one is where the motion model left the rig.
  anchored_[static_cast<std::size_t>(s)] = segment_ < 0 && !loaded_ ? 1 : 0;
  segment_ = s;
}

bool PlaceMemory::onlyReadsMap(const Odometry& odometry, const PoseEstimate& out) const {
  return out.state == TrackingState::Tracking && odometry.stats().initializations == initializations_seen_ &&
         odometry.rescales().empty() && odometry.settledKeyframes().empty() && !refinementDue(odometry) &&
         segment_ >= 0 && map_.placed(segment_) && !localize_only_;
}

void PlaceMemory::collectLoopDetection(bool wait) { loop_closer_.collectDetection(map_, wait); }

// Every segment is taken: one left without keyframes (culled, dropped when the run entered a saved map, or lost
// before its first keyframe) that no loop joined is made anew. Not while a correction is being solved: the graph
// names segments as they were.
int32_t PlaceMemory::reuseSegment(const SE3& T_w_o, bool placed) {
  if (loop_closer_.correcting()) return -1;
  for (int32_t s = 0; s < map_.segments(); ++s) {
    if (s == segment_ || map_.hasKeyframes(s) || !loop_closer_.alone(s)) continue;
    map_.reuseSegment(s, T_w_o, placed, segment_);
    ++stats_.segments_reused;
    return s;
  }
  return -1;
}

void PlaceMemory::addKeyframe(const Odometry& odometry, int odometry_slot) {
  collectLoopDetection(/*wait=*/true);  // the frame's keyframe before this one started one
  const Map& local = odometry.map();
  const Keyframe& kf = local.keyframe(odometry_slot);
  const SE3 T_w_k = map_.toWorld(segment_, kf.T_w_b);
  if (map_.size() == map_.capacity()) makeRoom();
  const int slot = map_.createKeyframe(segment_, kf.t, kf.frame_index, T_w_k, kf.T_w_b);
  if (slot < 0) {
    ++stats_.keyframes_dropped;
    return;
  }
  map_.setUnitSigma(slot, odometry.unitSigma());
  std::fill(own_points_.begin(), own_points_.end(), Eigen::Vector3f::Constant(std::nanf("")));
  gatherPoints(local, odometry.trackingRig(), kf, slot, own_points_);
  // One camera's window lets its unit drift from one keyframe to the next: its points stay as they were made.
  // (Each entry names a live keyframe of the odometry's pool, which has room for them all.)
  if (cameras_.size() > 1 && odometry.unitSigma() >= kUncertainUnit && kf.in_backend &&
      unrefined_count_ < unrefined_.size())
    unrefined_[unrefined_count_++] = {slot, odometry_slot, map_.keyframe(slot).id, kf.id};
  words_.compute(vocabulary_, kf.features);
  database_.insert(slot, words_.bow());
  ++stats_.keyframes;
  // SE(3) closures need a unit that holds between loops: a metric map, one whose uncertain unit its window holds, or
  // a rig without overlap whose unit the scale estimate knows to kUncertainUnit (the graph lets the odometry's
  // lengths give way by it, and the loops take the rescales that follow); Sim(3) ones (one camera) a unit that stays
  // put between loops.
  const ScaleStatus scale = odometry.rigState().scale();
  const bool closable = loop_closer_.similarity()
                            ? scale == ScaleStatus::Monocular
                            : scale == ScaleStatus::Metric || scale == ScaleStatus::Uncertain ||
                                  (scale == ScaleStatus::Unscaled && odometry.unitSigma() < kUncertainUnit);
  if (options_.loop_closure && closable) {
    loop_closer_.setRig(odometry.trackingRig());
    loop_closer_.startDetection(slot, kf.features, words_, map_, database_, own_points_);
    if (options_.repeatable) collectLoopDetection(/*wait=*/true);
  }
}

namespace {

// The point of the keyframe's ray closest to `p_b` (body frame, world unit; the lever arm is metric): a place is
// what its keyframe saw, so from the keyframe's own pose its points project onto its keypoints whatever depths the
// window's solve gave them. A window that fitted the start's motion in a unit not yet known leaves pixels of
// residual there, and a loop back to the place would fit a sideways shift to them: the solve gives the depth only.
Vec3 ontoObservedRay(const Vec3& p_b, const SE3& T_b_c, const Vec3& bearing_c) {
  const double depth = (T_b_c.inverse() * p_b).dot(bearing_c);
  return depth > 0 ? Vec3(T_b_c * (depth * bearing_c)) : p_b;
}

}  // namespace

void PlaceMemory::gatherPoints(const Map& local, const Rig& rig, const Keyframe& kf, int slot,
                               std::span<Eigen::Vector3f> own) {
  const SE3 T_k_o = kf.T_w_b.inverse();
  const double unit = map_.keyframe(slot).unit;  // the place map's points are in the world's unit
  // One camera's window has no metric lever arm for its unit to disagree with: its points fit its keyframes
  // already, and one keypoint's ray would only add that keypoint's noise.
  const bool on_rays = rig.size() > 1;
  const int levels_up = words_.directLevelsUp();
  ++gather_stamp_;
  for (int c = 0; c < kf.features.cameras(); ++c) {
    const auto& landmark_of = kf.landmark_of[static_cast<std::size_t>(c)];
    for (int k = 0; k < kf.features.sets[static_cast<std::size_t>(c)].count; ++k) {
      const int lm = landmark_of[static_cast<std::size_t>(k)];
      if (lm < 0 || !local.landmark(lm).alive || landmark_stamp_[static_cast<std::size_t>(lm)] == gather_stamp_)
        continue;
      landmark_stamp_[static_cast<std::size_t>(lm)] = gather_stamp_;
      const Landmark& l = local.landmark(lm);
      // Only points whose position is certain anchor a place: a multi-view point (depth to about 1%), or one the
      // back-end has seen from three keyframes; a young point triangulated across two keyframes is only as good as the
      // mapper's acceptance bound on its depth. (Odometry::startDeferredMapping relies on it: the new points of a
      // keyframe made in this frame, seen from it and one earlier keyframe, may not exist yet.)
      if (!l.metric && local.observingKeyframes(lm) < 3) continue;
      PlacePoint p;
      const Vec3 p_b = unit * (T_k_o * l.p_w);
      const bool seen = on_rays && kf.features.valid[static_cast<std::size_t>(c)][static_cast<std::size_t>(k)];
      const Vec3& bearing = kf.features.bearings[static_cast<std::size_t>(c)][static_cast<std::size_t>(k)];
      p.p_k = (seen ? ontoObservedRay(p_b, rig.T_b_c(c), bearing) : p_b).cast<float>();
      if (!own.empty()) own[static_cast<std::size_t>(c * features_per_camera_ + k)] = p.p_k;
      p.descriptor = l.descriptor;
      p.node = vocabulary_.ancestor(vocabulary_.word(l.descriptor), levels_up);
      p.cam = static_cast<int16_t>(c);
      p.octave = kf.features.sets[static_cast<std::size_t>(c)].keypoints[static_cast<std::size_t>(k)].octave;
      p.landmark_id = l.id + landmark_id_offset_;
      if (!map_.addPoint(slot, p)) break;
    }
  }
  map_.finishKeyframe(slot);
}

// A place made while the unit was uncertain took its points from a young map: the start's, triangulated across its
// short baselines (the first two keyframes of a start from two frames keep none), or one before its first scale
// estimate. When its keyframe leaves the odometry's window, every keyframe of the window has refined them and its
// pose: the place takes both then, so that its points and pose come from one estimate, as its neighbours' do.
void PlaceMemory::refinePlaces(const Odometry& odometry) {
  const Map& local = odometry.map();
  std::size_t waiting = 0;
  for (std::size_t i = 0; i < unrefined_count_; ++i) {
    const UnrefinedPlace u = unrefined_[i];
    if (!stillUnrefined(local, u)) continue;  // gone
    const Keyframe& kf = local.keyframe(u.odometry_slot);
    if (kf.in_backend) {
      unrefined_[waiting++] = u;
      continue;
    }
    collectLoopDetection(/*wait=*/true);  // it reads the points
    map_.refinePose(u.place_slot, kf.T_w_b);
    map_.clearPoints(u.place_slot);
    gatherPoints(local, odometry.trackingRig(), kf, u.place_slot, {});
    ++stats_.places_refined;
  }
  unrefined_count_ = waiting;
}

bool PlaceMemory::stillUnrefined(const Map& local, const UnrefinedPlace& u) const {
  const Keyframe& kf = local.keyframe(u.odometry_slot);
  const PlaceKeyframe& place = map_.keyframe(u.place_slot);
  return kf.alive && kf.id == u.odometry_id && place.alive && place.id == u.place_id;
}

bool PlaceMemory::refinementDue(const Odometry& odometry) const {
  const Map& local = odometry.map();
  for (std::size_t i = 0; i < unrefined_count_; ++i) {
    const UnrefinedPlace& u = unrefined_[i];
    if (!stillUnrefined(local, u) || !local.keyframe(u.odometry_slot).in_backend) return true;
  }
  return false;
}

void PlaceMemory::takeCorrection(bool wait) {
  if (!loop_closer_.takeCorrection(map_, wait)) return;
  ++world_revision_;
  propagatePlacement();
}

void PlaceMemory::makeRoom() {
  std::size_t n = 0;
  for (const LoopEdge& e : loop_closer_.loopEdges()) {
    kept_ids_[n++] = e.a;
    kept_ids_[n++] = e.b;
  }
  std::sort(kept_ids_.begin(), kept_ids_.begin() + static_cast<std::ptrdiff_t>(n));
  const int slot = map_.leastNeededKeyframe({kept_ids_.data(), n});
  if (slot < 0) return;
  database_.erase(slot);
  map_.eraseKeyframe(slot);
  if (last_place_keyframe_ == slot) last_place_keyframe_ = -1;
  ++stats_.keyframes_culled;
}

void PlaceMemory::relocalize(const FrameFeatures& frame, uint64_t frame_index, Odometry& odometry, PoseEstimate& out) {
  collectLoopDetection(/*wait=*/true);  // one started by this frame's keyframe shares the database's query
  ++stats_.relocalization_queries;
  words_.compute(vocabulary_, frame);
  relocalizer_.setRig(odometry.trackingRig());
  // Not on a keyframe of a map nowhere in the world (a run on a saved map, before it was recognized in it).
  const RelocalizationResult r =
      relocalizer_.locate(frame, words_, map_, database_, map_.newestKeyframe(), [&](int slot) {
        const int32_t s = map_.keyframe(slot).segment;
        return s != segment_ && !map_.placed(s);
      });
  if (!r.ok) return;
  spdlog::debug("place memory: frame {} at ({:.2f} {:.2f} {:.2f}) on keyframe {} of frame {} at ({:.2f} {:.2f} {:.2f})",
                frame_index, r.T_w_b.t.x(), r.T_w_b.t.y(), r.T_w_b.t.z(), map_.keyframe(r.keyframe).id,
                map_.keyframe(r.keyframe).frame_index, map_.keyframe(r.keyframe).T_w_k.t.x(),
                map_.keyframe(r.keyframe).T_w_k.t.y(), map_.keyframe(r.keyframe).T_w_k.t.z());
  // Lost before it was placed, and found in the saved map: the odometry continues in the world's frame.
  if (!map_.placed(segment_) && map_.placed(map_.keyframe(r.keyframe).segment)) {
    if (!enterWorld(frame_index)) return;
  }
  if (!resumeOdometry(frame, frame_index, odometry, r.T_w_b, out)) return;
  // The odometry goes on from a pose measured on that keyframe's points: in the world, if they are.
  if (anchored_[static_cast<std::size_t>(map_.keyframe(r.keyframe).segment)])
    anchored_[static_cast<std::size_t>(segment_)] = 1;
  ++stats_.relocalizations;
  stats_.last_relocalized_keyframe = map_.keyframe(r.keyframe).id;
  stats_.last_relocalized_frame = static_cast<int64_t>(frame_index);
  const Vec6 sigma = verifiedPoseSigma(r, options_);
  spdlog::info(
      "place memory: frame {} relocalized on place keyframe {} ({} inliers of {} candidates; sigma {:.3f} {:.3f} "
      "{:.3f} m, {:.2f} {:.2f} {:.2f} deg)",
      frame_index, map_.keyframe(r.keyframe).id, r.inliers, r.candidates, sigma[0], sigma[1], sigma[2],
      sigma[3] * 180 / M_PI, sigma[4] * 180 / M_PI, sigma[5] * 180 / M_PI);
  if (!localize_only_)
    for (const int32_t slot : odometry.settledKeyframes()) addKeyframe(odometry, slot);
}

bool PlaceMemory::resumeOdometry(const FrameFeatures& frame, uint64_t frame_index, Odometry& odometry, const SE3& T_w_b,
                                 PoseEstimate& out) {
  // Into the current segment's odometry frame (and unit): the odometry continues in it.
  const Sim3 S_o_w = map_.segmentSimilarity(segment_).inverse();
  int n = 0;
  for (const PlaceMatch& m : relocalizer_.inliers()) {
    MapSeed& seed = seeds_[static_cast<std::size_t>(n++)];
    seed.cam = m.cam;
    seed.kp = m.kp;
    seed.p_w = S_o_w * m.p_w;
    seed.descriptor = m.point->descriptor;
    seed.metric = true;
  }
  out.state = TrackingState::Lost;  // unless the odometry resumes
  out.valid = false;
  odometry.relocalize(frame, frame_index, map_.toOdometry(segment_, T_w_b),
                      std::span(seeds_.data(), static_cast<std::size_t>(n)), out);
  return out.state == TrackingState::Tracking;
}

// The run, not yet placed, was recognized in the saved map: its odometry goes on in a new segment whose frame is
// the world's, and what it mapped before (nowhere in the world, and of the same place) is dropped.
bool PlaceMemory::enterWorld(uint64_t frame_index) {
  const int32_t s = map_.createSegment(SE3(), /*placed=*/true);
  if (s < 0) return false;
  for (int slot = 0; slot < map_.capacity(); ++slot) {
    if (!map_.keyframe(slot).alive || map_.keyframe(slot).segment != segment_) continue;
    database_.erase(slot);
    map_.eraseKeyframe(slot);
  }
  segment_ = s;
  anchored_[static_cast<std::size_t>(s)] = 1;
  stats_.placed_frame = static_cast<int64_t>(frame_index);
  return true;
}

void PlaceMemory::place(const FrameFeatures& frame, uint64_t frame_index, const Odometry& odometry, const SE3& T_o_b) {
  collectLoopDetection(/*wait=*/true);  // one started by this frame's keyframe shares the database's query
  words_.compute(vocabulary_, frame);
  relocalizer_.setRig(odometry.trackingRig());
  const int32_t own = segment_;
  const RelocalizationResult r = relocalizer_.locate(frame, words_, map_, database_, last_place_keyframe_,
                                                     [&](int slot) { return map_.keyframe(slot).segment == own; });
  if (!r.ok || !map_.placed(map_.keyframe(r.keyframe).segment)) {
    pending_fix_ = false;
    return;
  }
  // Two recognitions in a row must agree on where the odometry's frame lies in the map.
  const SE3 T_w_o = map_.segmentPoseFor(segment_, r.T_w_b, T_o_b);
  const bool confirmed = pending_fix_ && sameCorrection(pending_T_w_o_, T_w_o, path_ - pending_path_);
  pending_fix_ = !confirmed;
  pending_T_w_o_ = T_w_o;
  pending_path_ = path_;
  if (!confirmed) return;
  last_place_keyframe_ = r.keyframe;
  if (!map_.placed(segment_)) {
    map_.moveSegment(segment_, T_w_o);
    map_.setPlaced(segment_);
    anchored_[static_cast<std::size_t>(segment_)] = 1;
    stats_.placed_frame = static_cast<int64_t>(frame_index);
    path_at_fix_ = path_;
    spdlog::info("place memory: frame {} recognized in the map on keyframe {} ({} inliers): poses are in its frame",
                 frame_index, map_.keyframe(r.keyframe).id, r.inliers);
    return;
  }
  // Localizing: the odometry drifts from the map, and a recognition corrects it, when the correction is beyond the
  // recognition's own uncertainty and within what the odometry can have drifted since the last one.
  const SE3 correction = map_.toWorld(segment_, T_o_b).inverse() * r.T_w_b;  // at the body
  const double travelled = path_ - path_at_fix_;
  const double angle_deg = so3Log(correction.R).norm() * 180.0 / M_PI;
  if (withinUncertainty(correction, verifiedPoseSigma(r, options_))) return;
  if (correction.t.norm() > options_.drift_floor_m + options_.drift_share * travelled ||
      angle_deg > options_.drift_floor_deg + options_.drift_deg_per_m * travelled) {
    spdlog::debug("place memory: frame {}: a recognition {:.2f} m, {:.1f} deg away after {:.1f} m: not a drift",
                  frame_index, correction.t.norm(), angle_deg, travelled);
    return;
  }
  spdlog::debug("place memory: frame {} on keyframe {} ({} inliers): localization corrected by {:.3f} m, {:.2f} deg",
                frame_index, map_.keyframe(r.keyframe).id, r.inliers, correction.t.norm(), angle_deg);
  map_.moveSegment(segment_, T_w_o);
  path_at_fix_ = path_;
  ++stats_.localization_corrections;
  ++world_revision_;
}

void PlaceMemory::propagatePlacement() {
  std::fill(root_placed_.begin(), root_placed_.end(), 0);
  std::fill(root_anchored_.begin(), root_anchored_.end(), 0);
  for (int32_t s = 0; s < map_.segments(); ++s) {
    if (map_.placed(s)) root_placed_[static_cast<std::size_t>(loop_closer_.root(s))] = 1;
    if (anchored_[static_cast<std::size_t>(s)]) root_anchored_[static_cast<std::size_t>(loop_closer_.root(s))] = 1;
  }
  for (int32_t s = 0; s < map_.segments(); ++s) {
    const auto root = static_cast<std::size_t>(loop_closer_.root(s));
    if (root_anchored_[root] && !anchored_[static_cast<std::size_t>(s)]) {
      anchored_[static_cast<std::size_t>(s)] = 1;
      if (s == segment_)
        spdlog::info("place memory: a loop joined this map to the one before the loss: poses are anchored");
    }
  }
  for (int32_t s = 0; s < map_.segments(); ++s) {
    if (map_.placed(s) || !root_placed_[static_cast<std::size_t>(loop_closer_.root(s))]) continue;
    map_.setPlaced(s);
    if (s == segment_) spdlog::info("place memory: a loop joined this run to the map: poses are in its frame");
  }
}

std::size_t PlaceMemory::maxMapBytes() const {
  return mapEnvelopeBytes() + mapHeaderBytes(static_cast<int>(cameras_.size())) + map_.maxWrittenBytes() +
         static_cast<std::size_t>(map_.capacity()) *
             keyframeWordsBytes(static_cast<std::size_t>(database_.maxWordsPerPlace())) +
         loop_closer_.maxWrittenBytes();
}

void PlaceMemory::writeMap(std::string& out) const {
  MapFileHeader& h = file_header_;
  h.cameras = cameras_;  // same size: no allocation
  h.vocabulary_words = static_cast<uint32_t>(vocabulary_.wordCount());
  h.vocabulary_fingerprint = vocabulary_fingerprint_;
  h.keyframes = h.max_points_per_keyframe = 0;
  h.points = 0;
  for (int slot = 0; slot < map_.capacity(); ++slot) {
    if (!map_.keyframe(slot).alive) continue;
    ++h.keyframes;
    const auto points = static_cast<uint32_t>(map_.keyframe(slot).point_count);
    h.points += points;
    h.max_points_per_keyframe = std::max(h.max_points_per_keyframe, points);
  }
  h.segments = static_cast<uint32_t>(map_.segments());
  h.loops = static_cast<uint32_t>(loop_closer_.loops());
  beginMapFile(out, h);
  ByteWriter w(out);
  map_.write(w);
  for (int slot = 0; slot < map_.capacity(); ++slot) {  // the order PlaceMap::write keeps
    if (!map_.keyframe(slot).alive) continue;
    putKeyframeWords(w, database_.entries(slot));
  }
  loop_closer_.write(w, map_.segments());
  finishMapFile(out);
}

void PlaceMemory::readMap(std::string_view bytes, const std::string& name, bool localize_only) {
  ByteReader in({}, name);
  const MapFileHeader h = openMapFile(bytes, name, in);
  const auto describe = [](const std::vector<MapFileHeader::Camera>& cameras) {
    std::string s = std::to_string(cameras.size()) + " cameras (";
    for (std::size_t c = 0; c < cameras.size(); ++c)
      s += (c ? ", " : "") + std::to_string(cameras[c].width) + "x" + std::to_string(cameras[c].height);
    return s + ")";
  };
  const bool same_cameras =
      h.cameras.size() == cameras_.size() &&
      std::equal(cameras_.begin(), cameras_.end(), h.cameras.begin(),
                 [](const auto& a, const auto& b) { return a.width == b.width && a.height == b.height; });
  if (!same_cameras)
    in.fail("the map was made by a rig of " + describe(h.cameras) + ", this one has " + describe(cameras_));
  if (h.vocabulary_words != static_cast<uint32_t>(vocabulary_.wordCount()) ||
      h.vocabulary_fingerprint != vocabulary_fingerprint_)
    in.fail("the map was made with another vocabulary (fingerprint " + std::to_string(h.vocabulary_fingerprint) +
            ", this one's " + std::to_string(vocabulary_fingerprint_) + "): its places cannot be recognized");
  const MapFileFields fields = MapFileFields::ofVersion(h.version);
  map_.read(in, static_cast<int>(cameras_.size()), fields);
  database_.clear();
  int64_t last_landmark = -1;
  for (int slot = 0; slot < map_.size(); ++slot) {
    takeKeyframeWords(in, vocabulary_.wordCount(), map_.keyframe(slot).id, "places.max_words_per_keyframe",
                      file_words_);
    database_.insert(slot, file_words_);
    for (const PlacePoint& p : map_.points(slot)) last_landmark = std::max(last_landmark, p.landmark_id);
  }
  loop_closer_.read(in, map_.segments(), fields.scales);
  if (in.remaining() != 0) in.fail(std::to_string(in.remaining()) + " bytes of trailing data");
  loaded_ = true;
  std::fill(anchored_.begin(), anchored_.end(), 0);
  for (int32_t s = 0; s < map_.segments(); ++s) anchored_[static_cast<std::size_t>(s)] = map_.placed(s) ? 1 : 0;
  localize_only_ = localize_only;
  landmark_id_offset_ = last_landmark + 1;
  segment_ = -1;
  last_place_keyframe_ = -1;
  unrefined_count_ = 0;
}

}  // namespace mcslam
