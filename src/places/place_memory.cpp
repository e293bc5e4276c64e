#include "mcslam/places/place_memory.hpp"

#include <spdlog/spdlog.h>

namespace mcslam {

PlaceMemory::PlaceMemory(const Rig& rig, const Vocabulary& vocabulary, const PlacesOptions& options,
                         const OdometryOptions& odometry_options, int max_features_per_camera)
    : vocabulary_(vocabulary),
      options_(options),
      map_(options.max_keyframes, options.max_points_per_keyframe),
      database_(vocabulary.wordCount(), options.max_keyframes, options.max_words_per_keyframe),
      words_(rig.size(), max_features_per_camera),
      relocalizer_(rig, options, odometry_options.scale_factor, max_features_per_camera),
      loop_closer_(rig, options, odometry_options.scale_factor, max_features_per_camera),
      seeds_(static_cast<std::size_t>(rig.size() * max_features_per_camera)),
      landmark_stamp_(static_cast<std::size_t>(odometry_options.max_landmarks), -1) {}

void PlaceMemory::afterOdometry(const FrameFeatures& frame, uint64_t frame_index, Odometry& odometry,
                                PoseEstimate& out) {
  followSegment(odometry);
  // Before the keyframes settled in this frame join: they are in the new unit already.
  for (const Odometry::Rescale& r : odometry.rescales()) map_.rescaleSegment(segment_, r.s, r.center);
  for (const int32_t slot : odometry.settledKeyframes()) addKeyframe(odometry, slot);
  if (out.state != TrackingState::Tracking && map_.size() > 0 && segment_ >= 0)
    relocalize(frame, frame_index, odometry, out);
  if (out.valid && segment_ >= 0) out.T_w_b = map_.segmentPose(segment_) * out.T_w_b;
  out.world_revision = world_revision_;
}

// A new odometry map (after a loss nothing bridged, or the very first) is a new segment. Its frame continues the
// old one's (the odometry starts it at the pose it coasted to), so it starts with the same T_w_o; a later
// recognition joins it to the map.
void PlaceMemory::followSegment(const Odometry& odometry) {
  if (odometry.stats().initializations == initializations_seen_) return;
  initializations_seen_ = odometry.stats().initializations;
  const SE3 T_w_o = segment_ >= 0 ? map_.segmentPose(segment_) : SE3();
  const int32_t s = map_.createSegment(T_w_o);
  if (s < 0) {
    spdlog::warn("place memory: more than {} odometry maps; the newest keeps the last one's frame",
                 PlaceMap::kMaxSegments);
    return;
  }
  segment_ = s;
}

void PlaceMemory::addKeyframe(const Odometry& odometry, int odometry_slot) {
  const Map& local = odometry.map();
  const Keyframe& kf = local.keyframe(odometry_slot);
  const SE3 T_w_k = map_.segmentPose(segment_) * kf.T_w_b;
  const int slot = map_.createKeyframe(segment_, kf.t, kf.frame_index, T_w_k, kf.T_w_b);
  if (slot < 0) {
    ++stats_.keyframes_dropped;
    return;
  }
  const SE3 T_k_o = kf.T_w_b.inverse();
  const int levels_up = words_.directLevelsUp();
  for (int c = 0; c < kf.features.cameras(); ++c) {
    const auto& landmark_of = kf.landmark_of[static_cast<std::size_t>(c)];
    for (int k = 0; k < kf.features.sets[static_cast<std::size_t>(c)].count; ++k) {
      const int lm = landmark_of[static_cast<std::size_t>(k)];
      if (lm < 0 || !local.landmark(lm).alive || landmark_stamp_[static_cast<std::size_t>(lm)] == kf.id) continue;
      landmark_stamp_[static_cast<std::size_t>(lm)] = kf.id;
      const Landmark& l = local.landmark(lm);
      // Only points whose position is certain anchor a place: a multi-view point (depth to about 1%), or one the
      // back-end has seen from three keyframes; a young point triangulated across two keyframes may be off by 15%.
      if (!l.metric && local.observingKeyframes(lm) < 3) continue;
      PlacePoint p;
      p.p_k = (T_k_o * l.p_w).cast<float>();
      p.descriptor = l.descriptor;
      p.node = vocabulary_.ancestor(vocabulary_.word(l.descriptor), levels_up);
      p.cam = static_cast<int16_t>(c);
      p.octave = kf.features.sets[static_cast<std::size_t>(c)].keypoints[static_cast<std::size_t>(k)].octave;
      p.landmark_id = l.id;
      if (!map_.addPoint(slot, p)) break;
    }
  }
  map_.finishKeyframe(slot);
  words_.compute(vocabulary_, kf.features);
  database_.insert(slot, words_.bow());
  ++stats_.keyframes;
  // SE(3) closures need a metric map: one whose unit is not known yet (or never will be: one camera) would need
  // Sim(3), which is not built yet.
  if (options_.loop_closure && odometry.rigState().metric()) {
    loop_closer_.setRig(odometry.trackingRig());
    if (loop_closer_.onKeyframe(slot, kf.features, words_, map_, database_)) ++world_revision_;
  }
}

void PlaceMemory::relocalize(const FrameFeatures& frame, uint64_t frame_index, Odometry& odometry, PoseEstimate& out) {
  ++stats_.relocalization_queries;
  words_.compute(vocabulary_, frame);
  relocalizer_.setRig(odometry.trackingRig());
  const RelocalizationResult r =
      relocalizer_.locate(frame, words_, map_, database_, map_.newestKeyframe(), [](int) { return false; });
  if (!r.ok) return;
  spdlog::debug("place memory: frame {} at ({:.2f} {:.2f} {:.2f}) on keyframe {} of frame {} at ({:.2f} {:.2f} {:.2f})",
                frame_index, r.T_w_b.t.x(), r.T_w_b.t.y(), r.T_w_b.t.z(), map_.keyframe(r.keyframe).id,
                map_.keyframe(r.keyframe).frame_index, map_.keyframe(r.keyframe).T_w_k.t.x(),
                map_.keyframe(r.keyframe).T_w_k.t.y(), map_.keyframe(r.keyframe).T_w_k.t.z());
  // Into the current segment's odometry frame: the odometry continues in it.
  const SE3 T_o_w = map_.segmentPose(segment_).inverse();
  int n = 0;
  for (const PlaceMatch& m : relocalizer_.inliers()) {
    MapSeed& seed = seeds_[static_cast<std::size_t>(n++)];
    seed.cam = m.cam;
    seed.kp = m.kp;
    seed.p_w = T_o_w * m.p_w;
    seed.descriptor = m.point->descriptor;
    seed.metric = true;
  }
  odometry.relocalize(frame, frame_index, T_o_w * r.T_w_b, std::span(seeds_.data(), static_cast<std::size_t>(n)), out);
  if (out.state != TrackingState::Tracking) return;
  ++stats_.relocalizations;
  stats_.last_relocalized_keyframe = map_.keyframe(r.keyframe).id;
  stats_.last_relocalized_frame = static_cast<int64_t>(frame_index);
  spdlog::info("place memory: frame {} relocalized on place keyframe {} ({} inliers of {} candidates)", frame_index,
               map_.keyframe(r.keyframe).id, r.inliers, r.candidates);
  for (const int32_t slot : odometry.settledKeyframes()) addKeyframe(odometry, slot);
}

}  // namespace mcslam
