#include "mcslam/places/loop_closer.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "pose_io.hpp"

namespace mcslam {

int32_t LoopCloser::findRoot(int32_t s) {
  std::vector<int32_t>& root = segment_root_;
  while (root[static_cast<std::size_t>(s)] != s)
    s = root[static_cast<std::size_t>(s)] = root[static_cast<std::size_t>(root[static_cast<std::size_t>(s)])];
  return s;
}

bool LoopCloser::alone(int32_t segment) {
  if (findRoot(segment) != segment) return false;
  for (int32_t s = 0; s < PlaceMap::kMaxSegments; ++s)
    if (s != segment && findRoot(s) == segment) return false;
  return true;
}

LoopCloser::LoopCloser(const Rig& rig, const PlacesOptions& options, float scale_factor, int max_features_per_camera,
                       bool similarity)
    : options_(options),
      verifier_(rig, options, scale_factor, max_features_per_camera),
      loops_(static_cast<std::size_t>(options.max_loops)),
      segment_root_(PlaceMap::kMaxSegments),
      roots_(PlaceMap::kMaxSegments),
      correction_(options.max_keyframes, options.max_loops, similarity),
      camera_centers_(rig.cameraCenters()),
      detect_features_(rig.size(), max_features_per_camera),
      detect_words_(rig.size(), max_features_per_camera),
      features_per_camera_(max_features_per_camera) {
  const auto keypoints = static_cast<std::size_t>(rig.size()) * static_cast<std::size_t>(max_features_per_camera);
  detect_own_points_.assign(keypoints, Eigen::Vector3f::Constant(std::nanf("")));
  scale_scratch_.resize(keypoints);
  detection_.closer = this;
  clear();
}

void LoopCloser::setRig(const Rig& rig) {
  verifier_.setRig(rig);
  rig.cameraCenters(camera_centers_);
}

void LoopCloser::clear() {
  detection_task_.collect();
  correction_wanted_ = false;
  loop_count_ = 0;
  for (int32_t s = 0; s < PlaceMap::kMaxSegments; ++s) segment_root_[static_cast<std::size_t>(s)] = s;
  pending_keyframe_ = -1;
  remeasured_keyframe_ = -1;
}

void LoopCloser::startDetection(int slot, const FrameFeatures& features, const FrameWords& words, const PlaceMap& map,
                                const PlaceDatabase& database, std::span<const Eigen::Vector3f> own_points) {
  // While the map's correction is being solved, its poses are about to move: a detection now would be measured
  // against the old ones (and find the loop just closed again).
  if (correcting()) {
    ++stats_.skipped;
    pending_keyframe_ = -1;
    return;
  }
  ++stats_.queries;
  detect_slot_ = slot;
  detect_keyframe_id_ = map.keyframe(slot).id;
  detect_map_ = &map;
  detect_database_ = &database;
  detect_features_ = features;  // same capacities: no allocation
  detect_words_ = words;
  const std::size_t n = std::min(own_points.size(), detect_own_points_.size());
  std::copy_n(own_points.begin(), n, detect_own_points_.begin());
  std::fill(detect_own_points_.begin() + static_cast<std::ptrdiff_t>(n), detect_own_points_.end(),
            Eigen::Vector3f::Constant(std::nanf("")));
  detection_task_.start(detection_);
}

void LoopCloser::detect() {
  const PlaceMap& map = *detect_map_;
  const PlaceKeyframe& k = map.keyframe(detect_slot_);
  const auto reachable = [&](int other) {
    const PlaceKeyframe& o = map.keyframe(other);
    return other == detect_slot_ || (o.segment == k.segment && k.id - o.id < options_.loop_min_keyframes_apart);
  };
  found_ = verifier_.locate(detect_features_, detect_words_, map, *detect_database_, -1, reachable);
  found_scale_ = LoopScale{};
  if (found_.ok && similarity()) {
    found_scale_ = loopScale(verifier_.inliers(), detect_own_points_, features_per_camera_, found_.T_w_b,
                             verifier_.rig(), scale_scratch_);
    found_.ok = found_scale_.ok;
  }
}

bool LoopCloser::collectDetection(PlaceMap& map, bool wait) {
  bool closed = false;
  // A decision may measure the loop again (remeasure): a caller that waits is about to write the map.
  while (detection_task_.running()) {
    if (!detection_task_.ready()) {
      if (!wait) break;
      ++stats_.waits;
    }
    detection_task_.collect();
    closed = decide(detect_slot_, found_, map) || closed;
  }
  return closed;
}

bool LoopCloser::decide(int slot, const RelocalizationResult& r, PlaceMap& map) {
  if (!r.ok) {
    pending_keyframe_ = -1;
    return false;
  }
  ++stats_.verified;
  if (!closesALoop(map, r.keyframe, slot)) {
    pending_keyframe_ = -1;
    return false;
  }
  const GroupUnits units = similarity() ? GroupUnits::Agree : settlePlaceUnits(slot, map);
  if (units == GroupUnits::Differ && remeasure(slot)) return false;  // the last keyframe's detection stays pending
  if (units != GroupUnits::Agree) {
    pending_keyframe_ = -1;
    return false;
  }
  const PlaceKeyframe& k = map.keyframe(slot);
  const int place = measuringPlace();
  const SE3 correction = r.T_w_b * k.T_w_k.inverse();  // moves the drifted keyframe onto the recognized place
  // In Sim(3), what moves the keyframe's surroundings (in its unit) onto the place's.
  const Sim3 similarity_correction = Sim3(r.T_w_b, found_scale_.scale) * Sim3(k.T_w_k).inverse();
  const int64_t candidate = map.keyframe(place).id;
  const bool confirmed = similarity() ? consistentWithLast(slot, map, similarity_correction, found_scale_)
                                      : consistentWithLast(slot, map, correction);
  spdlog::debug(
      "place memory: keyframe {} verified on keyframe {} ({} inliers): correction {:.3f} m, {:.2f} deg, "
      "scale {:.4f} +- {:.4f} ({} points){}",
      k.id, candidate, r.inliers, correction.t.norm(), so3Log(correction.R).norm() * 180 / M_PI, found_scale_.scale,
      found_scale_.sigma_log_scale, found_scale_.samples, confirmed ? ", confirmed" : "");
  pending_keyframe_ = k.id;
  pending_segment_ = k.segment;
  pending_candidate_ = candidate;
  pending_correction_ = correction;
  pending_similarity_correction_ = similarity_correction;
  pending_scale_ = found_scale_;
  if (!confirmed) return false;
  // A correction within the loop measurement's own uncertainty (chi-square, 6 dof, 95%; and the scale within two
  // of its standard deviations) says the map is consistent already: moving the world for it would only add the
  // measurement's noise to every published pose.
  const Vec6 sigma = verifiedPoseSigma(r, options_);
  const bool scale_agrees = !similarity() || std::abs(std::log(found_scale_.scale)) <= 2 * found_scale_.sigma_log_scale;
  if (withinUncertainty(correction, sigma) && scale_agrees) {
    ++stats_.consistent;
    pending_keyframe_ = -1;
    return false;
  }
  if (loop_count_ == static_cast<int>(loops_.size())) {
    spdlog::warn("place memory: {} loop closures kept; no room for another (places.max_loops)", loops_.size());
    return false;
  }
  // Kept in the two keyframes' odometry units, which later Sim(3) corrections do not change (their units do).
  const double unit_a = map.keyframe(place).unit, unit_b = k.unit;
  LoopEdge& loop = loops_[static_cast<std::size_t>(loop_count_++)];
  loop = {candidate, k.id, map.keyframe(place).T_w_k.inverse() * r.T_w_b, sigma, 1.0, 0.0};
  if (similarity()) {
    loop.T_a_b.t /= unit_a;
    loop.sigma.head<3>() /= unit_a;
    loop.scale = found_scale_.scale * unit_b / unit_a;
    loop.sigma_log_scale = found_scale_.sigma_log_scale;
  }
  const int32_t root_k = findRoot(k.segment);
  const int32_t root_c = findRoot(map.keyframe(place).segment);
  if (root_k != root_c) {
    segment_root_[static_cast<std::size_t>(std::max(root_k, root_c))] = std::min(root_k, root_c);
    ++stats_.merges;
  }
  accepted_ = {k.id, candidate, k.t, map.keyframe(place).t, r.inliers, correction};
  pending_keyframe_ = -1;
  correction_wanted_ = true;
  startCorrection(map);
  return true;
}

bool LoopCloser::takeCorrection(PlaceMap& map, bool wait) {
  const LoopCorrection::Outcome outcome = correction_.take(map, wait, camera_centers_);
  if (outcome == LoopCorrection::Outcome::Stale) {
    ++stats_.restarted;
    correction_wanted_ = true;
  }
  if (correction_wanted_ && !correction_.running()) startCorrection(map);
  if (outcome != LoopCorrection::Outcome::Applied) return false;
  ++stats_.closures;
  stats_.last_keyframe = accepted_.keyframe;
  stats_.last_candidate = accepted_.candidate;
  stats_.last_correction_m = accepted_.correction.t.norm();
  stats_.last_correction_deg = so3Log(accepted_.correction.R).norm() * 180.0 / M_PI;
  stats_.last_solve_ms = correction_.lastSolveMs();
  const backend::PoseGraphSummary& solved = correction_.lastSummary();
  spdlog::debug("place memory: pose graph of {} keyframes: {} iterations, cost {:.4g} -> {:.4g}", map.size(),
                solved.iterations, solved.initial_cost, solved.final_cost);
  spdlog::info(
      "place memory: loop closed: keyframe {} (t = {:.3f} s) sees keyframe {} (t = {:.3f} s) again ({} inliers); "
      "correction {:.3f} m, {:.2f} deg; pose graph solved in {:.1f} ms",
      accepted_.keyframe, toSeconds(accepted_.t_keyframe), accepted_.candidate, toSeconds(accepted_.t_candidate),
      accepted_.inliers, stats_.last_correction_m, stats_.last_correction_deg, stats_.last_solve_ms);
  return true;
}

void LoopCloser::followRescale(const PlaceMap& map, int32_t segment, double s, uint64_t from_frame) {
  if (similarity() || loop_count_ == 0) return;
  const auto rescaled = [&](int64_t id) {
    const int slot = map.slotOfId(id);
    return slot >= 0 && map.keyframe(slot).segment == segment && map.keyframe(slot).frame_index >= from_frame;
  };
  for (int i = 0; i < loop_count_; ++i) {
    LoopEdge& e = loops_[static_cast<std::size_t>(i)];
    if (!rescaled(e.a) || !rescaled(e.b)) continue;
    e.T_a_b.t *= s;
    e.sigma.head<3>() *= s;
  }
}

void LoopCloser::startCorrection(const PlaceMap& map) {
  const int segments = map.segments();
  for (int32_t s = 0; s < segments; ++s) roots_[static_cast<std::size_t>(s)] = findRoot(s);
  correction_.start(map, loopEdges(), {roots_.data(), static_cast<std::size_t>(segments)});
  correction_wanted_ = false;
}

// The verification matched the points of the candidate and its neighbours, each in the unit of its own time
// (PlaceUnit). Each camera's points of a place of uncertain unit are measured against this keyframe's own points
// on their own matches and take the unit they measured: hundreds of depths know it better than the odometry did.
// Per camera: before the unit was known, the motion was in one unit and the lever arms in metres, so each camera's
// depths came out in a unit of their own. When one was off beyond the measurement's error, so is the pose measured
// on it; once a measurement agrees with them, they are settled. A camera with too few matches of its own adds too
// little to the pose to decide.
LoopCloser::GroupUnits LoopCloser::settlePlaceUnits(int slot, PlaceMap& map) {
  const double own_sigma = map.keyframe(slot).unit_sigma;
  const int cameras = std::min(verifier_.rig().size(), 64);  // PlaceKeyframe::cameras_unit_measured's bits
  GroupUnits units = GroupUnits::Agree;
  for (const int32_t g : verifier_.group()) {
    const PlaceKeyframe& place = map.keyframe(g);
    if (place.unit_sigma < kUncertainUnit) continue;
    for (int cam = 0; cam < cameras; ++cam) {
      if ((place.cameras_unit_measured & (uint64_t{1} << cam)) || !matched(g, cam)) continue;
      if (own_sigma >= kUncertainUnit) {  // nothing surer to measure it with
        ++stats_.units_unmeasured;
        return GroupUnits::Unmeasurable;
      }
      const LoopScale own = loopScale(verifier_.inliers(), detect_own_points_, features_per_camera_, found_.T_w_b,
                                      verifier_.rig(), scale_scratch_, g, cam);
      const PlaceUnit unit = placeUnit(place.unit_sigma, own_sigma, own);
      if (unit == PlaceUnit::Unmeasured) continue;
      spdlog::debug(
          "place memory: keyframe {} finds camera {}'s points of keyframe {} {:.4f} +- {:.4f} times as far as its "
          "own ({} points): they take its unit",
          map.keyframe(slot).id, cam, place.id, own.scale, own.sigma_log_scale, own.samples);
      ++stats_.places_rescaled;
      if (unit == PlaceUnit::Other) {
        map.scalePoints(g, 1 / own.scale, camera_centers_, cam);
        units = GroupUnits::Differ;
      } else {
        map.takeMeasuredUnit(g, cam, 1 / own.scale, camera_centers_);
      }
    }
  }
  return units;
}

bool LoopCloser::matched(int place, int cam) const {
  for (const PlaceMatch& m : verifier_.inliers())
    if (m.keyframe == place && m.cam == cam) return true;
  return false;
}

// The loop is measured again, on the detection thread, on the points that took the keyframe's unit: once per
// keyframe. (decide()'s result is the detection's own, which the new one overwrites.)
bool LoopCloser::remeasure(int slot) {
  if (remeasured_keyframe_ == detect_keyframe_id_) return false;
  remeasured_keyframe_ = detect_keyframe_id_;
  ++stats_.remeasured;
  detect_slot_ = slot;
  detection_task_.start(detection_);
  return true;
}

// The database proposed the candidate for its words; the loop joins the place whose points measured it: the
// keyframe of the verified group with the most inliers. The candidate's neighbours can hold them all: the first
// keyframes of a map started from two frames keep no points (none was certain enough), and a loop joined to one of
// them would hold the rest of the map to where that keyframe happened to be.
int LoopCloser::measuringPlace() const {
  int best = -1, best_count = -1;
  for (const int32_t g : verifier_.group()) {
    int count = 0;
    for (const PlaceMatch& m : verifier_.inliers()) count += m.keyframe == g ? 1 : 0;
    if (count > best_count) {
      best = g;
      best_count = count;
    }
  }
  return best;
}

// A loop returns: within one segment, the path from the candidate to this keyframe must be much longer than
// their separation. Seeing a place far down a straight corridor again, after driving towards it, is tracking,
// not a loop, and its measurement (points far away) is the weakest there is. Another segment always closes one.
bool LoopCloser::closesALoop(const PlaceMap& map, int candidate, int slot) const {
  const PlaceKeyframe& c = map.keyframe(candidate);
  const PlaceKeyframe& k = map.keyframe(slot);
  if (c.segment != k.segment) return true;
  double path = 0;
  for (int s = candidate; s != slot && map.keyframe(s).next >= 0; s = map.keyframe(s).next)
    path += (map.keyframe(map.keyframe(s).next).T_o_k.t - map.keyframe(s).T_o_k.t).norm();
  const double separation = (k.T_o_k.t - c.T_o_k.t).norm();
  return path > options_.loop_min_path_ratio * separation + options_.loop_min_path_m;
}

// The detection of the keyframe before this one (same segment) found a correction that agrees with this one.
bool LoopCloser::followsLast(int slot, const PlaceMap& map) const {
  const PlaceKeyframe& k = map.keyframe(slot);
  return pending_keyframe_ >= 0 && pending_segment_ == k.segment && k.previous >= 0 &&
         map.keyframe(k.previous).id == pending_keyframe_;
}

bool LoopCloser::consistentWithLast(int slot, const PlaceMap& map, const SE3& correction) const {
  if (!followsLast(slot, map)) return false;
  const PlaceKeyframe& k = map.keyframe(slot);
  return sameCorrection(pending_correction_, correction,
                        (k.T_w_k.t - map.keyframe(k.previous).T_w_k.t).norm() + correction.t.norm());
}

// In Sim(3) the two similarities must move this keyframe alike (a rigid correction of a map whose unit is off
// changes from one keyframe to the next), and their scales agree within three standard deviations of the two
// measurements and the odometry's unit drift from one keyframe to the next.
bool LoopCloser::consistentWithLast(int slot, const PlaceMap& map, const Sim3& correction,
                                    const LoopScale& scale) const {
  if (!followsLast(slot, map)) return false;
  if (std::abs(std::log(scale.scale / pending_scale_.scale)) >
      3 * std::hypot(scale.sigma_log_scale, pending_scale_.sigma_log_scale, kOdometryLogScaleSigma))
    return false;
  const PlaceKeyframe& k = map.keyframe(slot);
  const Sim3 S_w_k(k.T_w_k);
  const Sim3 moved = correction * S_w_k;
  const SE3 difference = ((pending_similarity_correction_ * S_w_k).inverse() * moved).rigid();
  const double step = (k.T_w_k.t - map.keyframe(k.previous).T_w_k.t).norm();
  return sameCorrection(SE3(), difference, step + (moved.t - k.T_w_k.t).norm());
}

constexpr std::size_t kLoopBytes = 2 * sizeof(int64_t) + 12 * sizeof(double) + 6 * sizeof(double) + 2 * sizeof(double);

std::size_t loopFileBytes(bool with_scales) { return with_scales ? kLoopBytes : kLoopBytes - 2 * sizeof(double); }

std::size_t LoopCloser::maxWrittenBytes() const {
  return sizeof(uint32_t) + loops_.size() * kLoopBytes + PlaceMap::kMaxSegments * sizeof(int32_t);
}

void putLoops(ByteWriter& out, std::span<const LoopEdge> loops, std::span<const int32_t> roots) {
  out.put<uint32_t>(static_cast<uint32_t>(loops.size()));
  for (const LoopEdge& e : loops) {
    out.put<int64_t>(e.a);
    out.put<int64_t>(e.b);
    putPose(out, e.T_a_b);
    for (int k = 0; k < 6; ++k) out.put<double>(e.sigma[k]);
    out.put<double>(e.scale);
    out.put<double>(e.sigma_log_scale);
  }
  for (const int32_t root : roots) out.put<int32_t>(root);
}

int takeLoops(ByteReader& in, int segments, std::span<LoopEdge> loops, std::span<int32_t> roots, bool with_scales) {
  const auto count = in.take<uint32_t>("the loop count");
  if (count > loops.size())
    in.fail(std::to_string(count) + " loops, more than places.max_loops (" + std::to_string(loops.size()) + ")");
  for (uint32_t i = 0; i < count; ++i) {
    LoopEdge& e = loops[i];
    e.a = in.take<int64_t>("a loop's keyframe");
    e.b = in.take<int64_t>("a loop's keyframe");
    e.T_a_b = takePose(in, "a loop's relative pose");
    for (int k = 0; k < 6; ++k) e.sigma[k] = in.take<double>("a loop's uncertainty");
    if (!(e.sigma.minCoeff() > 0) || !e.sigma.allFinite()) in.fail("a loop with an uncertainty that is not positive");
    e.scale = with_scales ? in.take<double>("a loop's scale") : 1.0;
    e.sigma_log_scale = with_scales ? in.take<double>("a loop's scale uncertainty") : 0.0;
    if (!(e.scale > 0) || !std::isfinite(e.scale) || !(e.sigma_log_scale >= 0) || !std::isfinite(e.sigma_log_scale))
      in.fail("a loop with a scale that is not positive");
  }
  // Joining always hangs the larger root under the smaller: a root that is not below its segment is no union.
  for (int s = 0; s < segments; ++s) {
    const auto r = in.take<int32_t>("a segment's root");
    if (r < 0 || r > s) in.fail("segment " + std::to_string(s) + " joined to segment " + std::to_string(r));
    roots[static_cast<std::size_t>(s)] = r;
  }
  return static_cast<int>(count);
}

void LoopCloser::write(ByteWriter& out, int segments) const {
  putLoops(out, {loops_.data(), static_cast<std::size_t>(loop_count_)},
           {segment_root_.data(), static_cast<std::size_t>(segments)});
}

void LoopCloser::read(ByteReader& in, int segments, bool with_scales) {
  clear();  // before the first frame: nothing is being solved
  loop_count_ = takeLoops(in, segments, loops_, segment_root_, with_scales);
}

}  // namespace mcslam
