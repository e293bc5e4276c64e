#include "mcslam/pipeline/slam_pipeline.hpp"

#include <chrono>

#include "mcslam/core/binary_io.hpp"

namespace mcslam {

OdometryOptions effectiveOdometryOptions(const PipelineConfig& config, const OverlapMap& overlap) {
  OdometryOptions o = config.odometry;
  if (config.refine_extrinsics == RefineExtrinsics::On) {
    o.refine_extrinsics = true;
  } else if (config.refine_extrinsics == RefineExtrinsics::Off) {
    o.refine_extrinsics = false;
  } else {
    // A camera that overlaps no other could not be calibrated against a shared target: its extrinsic
    // was chained (through an IMU) and deserves refinement. Not when no two cameras overlap: the map's
    // metric scale then comes from the calibrated lever arms alone, and refining them with it lets both
    // shrink together until the map collapses (docs/design/stages.md).
    bool isolated = false, any_pair = false;
    for (int i = 0; i < overlap.cameras() && overlap.cameras() > 1; ++i) {
      bool any = false;
      for (int j = 0; j < overlap.cameras(); ++j) any = any || overlap.overlaps(i, j) || overlap.overlaps(j, i);
      isolated = isolated || !any;
      any_pair = any_pair || any;
    }
    o.refine_extrinsics = isolated && any_pair;
  }
  return o;
}

SlamPipeline::SlamPipeline(const Rig& rig, const PipelineConfig& config)
    : rig_(rig),
      config_(config),
      front_end_(rig_, config_),
      odometry_(rig_, effectiveOdometryOptions(config_, front_end_.overlap()), config_.orb.max_features),
      features_(rig_.size(), config_.orb.max_features) {
  // Two: one being prepared while the other is finished.
  for (int k = 0; k < 2; ++k) stages_.push_back(Stage{FrameFeatures(rig_.size(), config_.orb.max_features), 0, 0, {}});
  handover_ = effectiveOdometryOptions(config_, front_end_.overlap()).refine_extrinsics && rig_.size() > 1;
  if (config_.places.enabled) {
    vocabulary_ = std::make_unique<Vocabulary>(loadVocabulary(config_.places.vocabulary));
    places_ =
        std::make_unique<PlaceMemory>(rig_, *vocabulary_, config_.places, config_.odometry, config_.orb.max_features);
  }
  if (handover_) rig_after_.assign(2, RigState(rig_));
}

void SlamPipeline::computeFeatures(const RigFrameView& frame, FrameFeatures& out, PipelineTiming& timing) {
  if (handover_) {
    if (features_computed_ >= 2) {  // the first two frames keep the calibration
      const RigState& s = rig_after_[features_computed_ % 2];
      for (int c = 0; c < rig_.size(); ++c)
        front_end_.setBodyFromCamera(c, s.reestimated(c) ? s.T_b_c(c) : rig_.T_b_c(c));
    }
    ++features_computed_;
  }
  front_end_.compute(frame, out);
  const FrontEndTiming& f = front_end_.timing();
  timing.features_ms = f.extraction_ms + f.multiview_ms;
}

void SlamPipeline::track(const FrameFeatures& features, uint64_t sequence, Timestamp t, PoseEstimate& out,
                         PipelineTiming& timing) {
  odometry_.process(features, sequence, out);
  if (places_) {
    const auto start = std::chrono::steady_clock::now();
    places_->afterOdometry(features, sequence, odometry_, out);
    timing.places_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  noteInitialization();
  odometry_.startDeferredMapping();  // place memory is done with the frame's landmarks
  if (handover_) {
    rig_after_[frames_tracked_ % 2].follow(odometry_.rigState());  // by value, allocates nothing
    ++frames_tracked_;
  }
  out.t = t;
  const OdometryTiming& o = odometry_.timing();
  timing.tracking_ms = o.tracking_ms + o.mapping_ms;
  timing.optimization_ms = o.backend_ms;
}

// The start's poses in the world frame, as place memory moved the frame's (the same segment).
void SlamPipeline::noteInitialization() {
  initialization_ = odometry_.lastInitialization();
  if (initialization_.start < 0 || !places_) return;
  if (!places_->toWorld(initialization_.T_w_reference, initialization_.T_w_reference) ||
      !places_->toWorld(initialization_.T_w_start, initialization_.T_w_start)) {
    initialization_ = Odometry::InitializationSpan{};
  }
}

void SlamPipeline::prepare(const RigFrameView& frame, int slot) {
  Stage& s = stages_[static_cast<std::size_t>(slot)];
  const auto start = std::chrono::steady_clock::now();
  s.timing = PipelineTiming{};
  computeFeatures(frame, s.features, s.timing);
  s.sequence = frame.sequence;
  s.t = frame.t;
  s.timing.total_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void SlamPipeline::finish(int slot, PoseEstimate& out) {
  Stage& s = stages_[static_cast<std::size_t>(slot)];
  const auto start = std::chrono::steady_clock::now();
  track(s.features, s.sequence, s.t, out, s.timing);
  s.timing.total_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  timing_ = s.timing;
}

void SlamPipeline::process(const RigFrameView& frame, PoseEstimate& out) {
  const auto start = std::chrono::steady_clock::now();
  computeFeatures(frame, features_, timing_);
  track(features_, frame.sequence, frame.t, out, timing_);
  timing_.total_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void SlamPipeline::flush() {
  odometry_.flush();
  if (places_) places_->flush();
}

uint64_t SlamPipeline::backgroundThreadAllocations() const {
  return odometry_.backendThreadAllocations() + (places_ ? places_->threadAllocations() : 0);
}

void SlamPipeline::loadMap(const std::string& path, bool localize_only) {
  if (!places_) throw InputError(path + ": a map needs place memory, which places.enabled turns off");
  places_->readMap(readFileBounded(path, kMaxMapFileBytes, "map file"), path, localize_only);
}

bool SlamPipeline::placeCounters(PlaceCounters& out) const {
  if (!places_) return false;
  out.relocalizations = places_->stats().relocalizations;
  out.loop_closures = places_->loopStats().closures;
  out.map_merges = places_->loopStats().merges;
  out.localization_corrections = places_->stats().localization_corrections;
  out.keyframes = places_->map().size();
  out.keyframes_culled = places_->stats().keyframes_culled;
  out.world_revision = places_->worldRevision();
  return true;
}

bool SlamPipeline::writeMap(std::string& out) const {
  if (!places_) return false;
  places_->writeMap(out);
  return true;
}

void SlamPipeline::keyframes(std::vector<KeyframePose>& out) const {
  out.clear();
  if (places_) {  // the whole map, in the world frame, as loop closures left it
    const PlaceMap& map = places_->map();
    for (int i = 0; i < map.capacity(); ++i) {
      const PlaceKeyframe& kf = map.keyframe(i);
      if (kf.alive) out.push_back(KeyframePose{kf.id, kf.t, kf.T_w_k});
    }
    return;
  }
  const Map& map = odometry_.map();
  for (int i = 0; i < map.keyframeCapacity(); ++i) {
    const Keyframe& kf = map.keyframe(i);
    if (kf.alive) out.push_back(KeyframePose{kf.id, kf.t, kf.T_w_b});
  }
}

}  // namespace mcslam
