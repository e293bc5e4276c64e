#include "run_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "mcslam/core/error.hpp"
#include "mcslam/core/json_writer.hpp"
#include "mcslam/core/synced_file.hpp"

namespace mcslam::run {

bool RunReport::add(const PoseEstimate& pose, const PipelineTiming& timing) {
  FrameRecord r;
  r.t = pose.t;
  r.pose = pose;
  r.timing = timing;
  const bool changed = frames_.empty() || frames_.back().pose.state != pose.state;
  if (changed) changes_.push_back(StateChange{frames_.size(), pose.t, pose.state});
  if (pose.valid && pose.state == TrackingState::Tracking) {
    last_tracked_unscaled_ = !pose.metric;
    last_tracked_roughly_metric_ = pose.roughly_metric;
  }
  frames_.push_back(r);
  return changed;
}

void RunReport::backfill(const Odometry::InitializationSpan& start, uint64_t seen_index) {
  if (start.reference < 0 || start.start <= start.reference || seen_index >= frames_.size() ||
      static_cast<uint64_t>(start.start) >= seen_index)
    return;
  const auto reference_index = static_cast<uint64_t>(start.reference);
  const auto init_index = static_cast<uint64_t>(start.start);
  // Every frame from the reference to the start gets a pose in the unit the map started in.
  const auto posed = [&](uint64_t i, const SE3& T_w_b) {
    FrameRecord& r = frames_[i];
    r.pose.T_w_b = T_w_b;
    r.pose.valid = true;
    r.pose.metric = start.metric;
    r.pose.roughly_metric = start.roughly_metric;
  };
  posed(init_index, start.T_w_start);
  frames_[init_index].map_start = true;
  const SE3 a = start.T_w_reference;
  const SE3 b = start.T_w_start;
  posed(reference_index, a);
  const Vec6 xi = (a.inverse() * b).log();
  for (uint64_t i = reference_index + 1; i < init_index; ++i) {
    const double s = static_cast<double>(i - reference_index) / static_cast<double>(init_index - reference_index);
    posed(i, a * SE3::exp(s * xi));
    frames_[i].interpolated = true;
  }
}

void RunReport::noteKeyframes(const std::vector<KeyframePose>& keyframes) {
  for (const KeyframePose& kf : keyframes) keyframes_[kf.id] = StampedPose{kf.t, kf.T_w_b};
}

Trajectory RunReport::trajectory() const {
  Trajectory out;
  for (const FrameRecord& r : frames_) {
    if (r.pose.valid) out.push_back(StampedPose{r.t, r.pose.T_w_b});
  }
  return out;
}

Trajectory RunReport::keyframes() const {
  Trajectory out;
  for (const auto& [id, p] : keyframes_) out.push_back(p);
  std::sort(out.begin(), out.end(), [](const StampedPose& a, const StampedPose& b) { return a.t < b.t; });
  return out;
}

namespace {

struct Summary {
  double mean = 0, p99 = 0, max = 0;
};

Summary summarize(std::vector<double> v) {
  Summary s;
  if (v.empty()) return s;
  double sum = 0;
  for (double x : v) sum += x;
  s.mean = sum / static_cast<double>(v.size());
  std::sort(v.begin(), v.end());
  s.p99 = v[std::min(v.size() - 1, static_cast<std::size_t>(0.99 * static_cast<double>(v.size() - 1) + 0.5))];
  s.max = v.back();
  return s;
}

}  // namespace

void RunReport::writeFrameTimes(const std::string& path, std::span<const std::size_t> dataset_index) const {
  // frame: the run's own count, as in the stats file's state changes; dataset_frame: the dataset's index.
  std::string csv =
      "frame,dataset_frame,t,state,keyframe,features_ms,tracking_ms,optimization_ms,place_memory_ms,total_ms\n";
  char line[256];
  for (std::size_t i = 0; i < frames_.size() && i < dataset_index.size(); ++i) {
    const FrameRecord& r = frames_[i];
    std::snprintf(line, sizeof(line), "%zu,%zu,%.6f,%s,%d,%.3f,%.3f,%.3f,%.3f,%.3f\n", i, dataset_index[i],
                  toSeconds(r.t), trackingStateName(r.pose.state), r.pose.is_keyframe ? 1 : 0, r.timing.features_ms,
                  r.timing.tracking_ms, r.timing.optimization_ms, r.timing.places_ms, r.timing.total_ms);
    csv += line;
  }
  std::string error;
  if (!writeFileSynced(path, csv, &error)) throw InputError("--frame-times: " + error);
}

void RunReport::writeStats(const std::string& path, const SlamPipeline& pipeline, const std::string& dataset,
                           int cameras, double wall_seconds) const {
  std::ofstream out(path, std::ios::trunc);
  if (!out) throw InputError(path + ": cannot write stats file");
  std::vector<double> features, tracking, optimization, place_memory, total;
  uint64_t state_count[4] = {0, 0, 0, 0};
  int interpolated = 0, map_starts = 0, unknown_scale = 0, roughly_metric = 0, unanchored = 0;
  for (const FrameRecord& r : frames_) {
    features.push_back(r.timing.features_ms);
    tracking.push_back(r.timing.tracking_ms);
    optimization.push_back(r.timing.optimization_ms);
    place_memory.push_back(r.timing.places_ms);
    total.push_back(r.timing.total_ms);
    ++state_count[static_cast<int>(r.pose.state)];
    interpolated += r.interpolated ? 1 : 0;
    map_starts += r.map_start ? 1 : 0;
    unknown_scale += r.unknownScale() ? 1 : 0;
    roughly_metric += r.unknownScale() && r.pose.roughly_metric ? 1 : 0;
    unanchored += r.pose.unanchored ? 1 : 0;
  }
  const OdometryStats& s = pipeline.stats();
  JsonWriter j(out);
  j.beginObject();
  j.key("dataset").value(dataset);
  j.key("cameras").value(cameras);
  j.key("frames").value(static_cast<unsigned long long>(frames_.size()));
  j.key("wall_seconds").value(wall_seconds);
  // Throughput (with the stages overlapping, the default, it can be below the per-frame latency, timing_ms.total).
  j.key("wall_ms_per_frame").value(frames_.empty() ? 0.0 : 1000.0 * wall_seconds / static_cast<double>(frames_.size()));
  j.key("tracking_states").beginObject();
  j.key("tracking").value(state_count[static_cast<int>(TrackingState::Tracking)]);
  j.key("not_initialized").value(state_count[static_cast<int>(TrackingState::NotInitialized)]);
  j.key("lost").value(state_count[static_cast<int>(TrackingState::Lost)]);
  j.key("localizing").value(state_count[static_cast<int>(TrackingState::Localizing)]);
  // Valid poses whose place in the world was the motion model's guess (a new map after an unbridged loss, not
  // yet joined to the old one: PoseEstimate::unanchored).
  j.key("unanchored").value(unanchored);
  j.endObject();
  // Where tracking was lost and regained: every change of state, with its frame index and time.
  j.key("state_changes").beginArray();
  for (const StateChange& c : changes_) {
    j.beginObject();
    j.key("frame").value(static_cast<unsigned long long>(c.frame));
    j.key("t").value(toSeconds(c.t));
    j.key("state").value(trackingStateName(c.state));
    j.endObject();
  }
  j.endArray();
  j.key("interpolated_before_initialization").value(interpolated);
  // Frames a map from two frames started at: published as not initialized (their attempt was taken at the next
  // frame), written to the trajectory with their keyframe's pose.
  j.key("map_starts_posed_afterwards").value(map_starts);
  // A rig without overlap starts up to scale: its poses have an arbitrary unit until the back-end's window
  // fixes the scale (frame of convergence; -1: the map started metric, or never converged). One camera's
  // poses are all up to scale (frames_unknown_scale counts them). Overlapping cameras that see their common points
  // too far for their baseline start in roughly metric units (counted among them, and in frames_roughly_metric)
  // until a keyframe sees enough metric points (converged_frame).
  j.key("scale").beginObject();
  j.key("converged_frame").value(static_cast<long long>(s.scale_converged_frame));
  j.key("frames_unknown_scale").value(unknown_scale);
  j.key("frames_roughly_metric").value(roughly_metric);
  j.key("estimates").value(s.scale_estimates);
  j.key("rescales").value(s.scale_rescales);
  j.key("last_factor").value(s.last_scale);
  j.key("last_relative_sigma").value(std::isfinite(s.last_scale_sigma) ? s.last_scale_sigma : -1.0);
  j.key("combined_relative_sigma").value(std::isfinite(s.combined_scale_sigma) ? s.combined_scale_sigma : -1.0);
  j.endObject();
  j.key("initializations").value(s.initializations);
  j.key("keyframes").value(s.keyframes);
  j.key("recoveries").value(s.recoveries);
  j.key("extrinsic_reestimations").value(s.extrinsic_reestimations);
  j.key("stamps_not_increasing").value(s.stamps_not_increasing);
  j.key("rejected_images").value(pipeline.rejectedImages());
  if (const PlaceMemory* places = pipeline.places()) {
    const PlaceStats& p = places->stats();
    j.key("places").beginObject();
    j.key("keyframes").value(p.keyframes);
    j.key("keyframes_dropped").value(p.keyframes_dropped);
    j.key("keyframes_culled").value(p.keyframes_culled);
    j.key("relocalization_queries").value(p.relocalization_queries);
    j.key("relocalizations").value(p.relocalizations);
    j.key("segments").value(places->map().segments());  // odometry maps started, the first one included
    j.key("segments_reused").value(p.segments_reused);
    j.key("places_refined").value(p.places_refined);  // places of an uncertain unit that took refined points
    j.key("last_relocalized_frame").value(static_cast<long long>(p.last_relocalized_frame));
    const LoopStats& l = places->loopStats();
    j.key("loop_queries").value(l.queries);
    j.key("loops_verified").value(l.verified);
    j.key("loops_consistent").value(l.consistent);
    j.key("loop_closures").value(l.closures);
    j.key("map_merges").value(l.merges);
    j.key("loop_places_rescaled").value(l.places_rescaled);  // a place camera's points took a unit a loop measured
    j.key("loop_remeasured").value(l.remeasured);            // loops measured again on them at once
    j.key("loop_units_unmeasured").value(l.units_unmeasured);
    j.key("loop_queries_skipped").value(l.skipped);  // while a correction was being solved
    j.key("loop_detection_waits").value(l.waits);    // frames that waited for the detection thread (--live)
    j.key("world_revision").value(static_cast<unsigned long long>(places->worldRevision()));
    j.key("map_loaded").value(places->mapLoaded());
    j.key("placed_frame").value(static_cast<long long>(p.placed_frame));  // first frame recognized in the loaded map
    j.key("localization_corrections").value(p.localization_corrections);
    j.key("place_keyframes").value(static_cast<long long>(places->map().size()));  // in the map now, loaded included
    j.endObject();
  }
  j.key("allocations_after_warmup").beginObject();
  j.key("counted").value(allocations_.counted);
  j.key("warmup_frames").value(static_cast<unsigned long long>(allocations_.warmup_frames));
  j.key("front_end_thread").value(static_cast<unsigned long long>(allocations_.front_end));
  j.key("tracking_thread").value(static_cast<unsigned long long>(allocations_.tracking));
  j.key("background_threads").value(static_cast<unsigned long long>(allocations_.background));
  j.endObject();
  j.key("timing_ms").beginObject();
  const std::pair<const char*, Summary> stages[] = {{"feature_extraction", summarize(features)},
                                                    {"tracking_and_mapping", summarize(tracking)},
                                                    {"optimization", summarize(optimization)},
                                                    {"place_memory", summarize(place_memory)},
                                                    {"total", summarize(total)}};
  for (const auto& [name, sum] : stages) {
    j.key(name).beginObject();
    j.key("mean").value(sum.mean);
    j.key("p99").value(sum.p99);
    j.key("max").value(sum.max);
    j.endObject();
  }
  j.endObject();
  j.endObject();
  out.flush();  // a full disk shows only when the buffer goes out
  if (!out) throw InputError(path + ": cannot write stats file (write failed)");
}

}  // namespace mcslam::run
