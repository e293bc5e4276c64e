#include "mcslam/places/loop_closer.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>

#include "pose_io.hpp"

namespace mcslam {

namespace {

// The odometry's relative pose between consecutive keyframes: about 1% of the distance and of the angle, plus a
// floor (a keyframe pair that hardly moved is still only known to a few millimetres and a tenth of a degree).
Vec6 odometrySigma(const SE3& T_a_b) {
  const double d = T_a_b.t.norm();
  const double angle = so3Log(T_a_b.R).norm();
  Vec6 s;
  s.head<3>().setConstant(0.005 + 0.01 * d);
  s.tail<3>().setConstant(0.002 + 0.01 * angle + 0.001 * d);
  return s;
}

}  // namespace

int32_t LoopCloser::findRoot(int32_t s) {
  std::vector<int32_t>& root = segment_root_;
  while (root[static_cast<std::size_t>(s)] != s)
    s = root[static_cast<std::size_t>(s)] = root[static_cast<std::size_t>(root[static_cast<std::size_t>(s)])];
  return s;
}

LoopCloser::LoopCloser(const Rig& rig, const PlacesOptions& options, float scale_factor, int max_features_per_camera)
    : options_(options),
      verifier_(rig, options, scale_factor, max_features_per_camera),
      graph_(options.max_keyframes, 2 * options.max_keyframes + options.max_loops),
      loops_(static_cast<std::size_t>(options.max_loops)),
      node_of_slot_(static_cast<std::size_t>(options.max_keyframes), -1),
      slot_of_node_(static_cast<std::size_t>(options.max_keyframes), -1),
      segment_root_(PlaceMap::kMaxSegments) {
  clear();
}

void LoopCloser::clear() {
  loop_count_ = 0;
  for (int32_t s = 0; s < PlaceMap::kMaxSegments; ++s) segment_root_[static_cast<std::size_t>(s)] = s;
  pending_keyframe_ = -1;
}

bool LoopCloser::onKeyframe(int slot, const FrameFeatures& features, const FrameWords& words, PlaceMap& map,
                            const PlaceDatabase& database) {
  const PlaceKeyframe& k = map.keyframe(slot);
  const auto reachable = [&](int other) {
    const PlaceKeyframe& o = map.keyframe(other);
    return other == slot || (o.segment == k.segment && k.id - o.id < options_.loop_min_keyframes_apart);
  };
  ++stats_.queries;
  const RelocalizationResult r = verifier_.locate(features, words, map, database, -1, reachable);
  if (!r.ok) {
    pending_keyframe_ = -1;
    return false;
  }
  ++stats_.verified;
  if (!closesALoop(map, r.keyframe, slot)) {
    pending_keyframe_ = -1;
    return false;
  }
  const SE3 correction = r.T_w_b * k.T_w_k.inverse();  // moves the drifted keyframe onto the recognized place
  const int64_t candidate = map.keyframe(r.keyframe).id;
  const bool confirmed = consistentWithLast(slot, map, correction);
  pending_keyframe_ = k.id;
  pending_segment_ = k.segment;
  pending_candidate_ = candidate;
  pending_correction_ = correction;
  if (!confirmed) return false;
  // A correction within the loop measurement's own uncertainty (chi-square, 6 dof, 95%) says the map is consistent
  // already: moving the world for it would only add the measurement's noise to every published pose.
  const Vec6 sigma = verifiedPoseSigma(r, options_);
  if (withinUncertainty(correction, sigma)) {
    ++stats_.consistent;
    pending_keyframe_ = -1;
    return false;
  }
  if (loop_count_ == static_cast<int>(loops_.size())) {
    spdlog::warn("place memory: {} loop closures kept; no room for another (places.max_loops)", loops_.size());
    return false;
  }
  loops_[static_cast<std::size_t>(loop_count_++)] = {candidate, k.id,
                                                     map.keyframe(r.keyframe).T_w_k.inverse() * r.T_w_b, sigma};
  const int32_t root_k = findRoot(k.segment);
  const int32_t root_c = findRoot(map.keyframe(r.keyframe).segment);
  if (root_k != root_c) {
    segment_root_[static_cast<std::size_t>(std::max(root_k, root_c))] = std::min(root_k, root_c);
    ++stats_.merges;
  }
  const auto start = std::chrono::steady_clock::now();
  correct(map);
  stats_.last_solve_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  ++stats_.closures;
  stats_.last_keyframe = k.id;
  stats_.last_candidate = candidate;
  stats_.last_correction_m = correction.t.norm();
  stats_.last_correction_deg = so3Log(correction.R).norm() * 180.0 / M_PI;
  spdlog::info(
      "place memory: loop closed: keyframe {} (t = {:.3f} s) sees keyframe {} (t = {:.3f} s) again ({} inliers); "
      "correction {:.3f} m, {:.2f} deg; pose graph solved in {:.1f} ms",
      k.id, toSeconds(k.t), candidate, toSeconds(map.keyframe(r.keyframe).t), r.inliers, stats_.last_correction_m,
      stats_.last_correction_deg, stats_.last_solve_ms);
  pending_keyframe_ = -1;
  return true;
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
bool LoopCloser::consistentWithLast(int slot, const PlaceMap& map, const SE3& correction) const {
  const PlaceKeyframe& k = map.keyframe(slot);
  if (pending_keyframe_ < 0 || pending_segment_ != k.segment || k.previous < 0 ||
      map.keyframe(k.previous).id != pending_keyframe_)
    return false;
  return sameCorrection(pending_correction_, correction,
                        (k.T_w_k.t - map.keyframe(k.previous).T_w_k.t).norm() + correction.t.norm());
}

void LoopCloser::correct(PlaceMap& map) {
  buildGraph(map);
  graph_.optimize();
  for (int node = 0; node < graph_.nodes(); ++node)
    map.setKeyframePose(slot_of_node_[static_cast<std::size_t>(node)], graph_.pose(node));
  // Each segment's odometry frame follows its newest keyframe: the odometry goes on from where the map now puts it.
  for (int32_t s = 0; s < map.segments(); ++s) {
    const int newest = segmentEnd(map, s, /*oldest=*/false);
    if (newest >= 0) map.setSegmentPose(s, map.keyframe(newest).T_w_k * map.keyframe(newest).T_o_k.inverse());
  }
}

int LoopCloser::segmentEnd(const PlaceMap& map, int32_t segment, bool oldest) const {
  for (int slot = 0; slot < map.capacity(); ++slot) {
    const PlaceKeyframe& k = map.keyframe(slot);
    if (k.alive && k.segment == segment && (oldest ? k.previous : k.next) < 0) return slot;
  }
  return -1;
}

int LoopCloser::slotOfId(const PlaceMap& map, int64_t id) const {
  for (int slot = 0; slot < map.capacity(); ++slot)
    if (map.keyframe(slot).alive && map.keyframe(slot).id == id) return slot;
  return -1;
}

constexpr std::size_t kLoopBytes = 2 * sizeof(int64_t) + 12 * sizeof(double) + 6 * sizeof(double);

std::size_t loopFileBytes() { return kLoopBytes; }

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
  }
  for (const int32_t root : roots) out.put<int32_t>(root);
}

int takeLoops(ByteReader& in, int segments, std::span<LoopEdge> loops, std::span<int32_t> roots) {
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

void LoopCloser::read(ByteReader& in, int segments) {
  clear();
  loop_count_ = takeLoops(in, segments, loops_, segment_root_);
}

// Nodes: every place keyframe, in slot order. Edges: consecutive keyframes of a segment (the odometry's relative
// pose), and the loops. Each set of segments joined by loops is held by the oldest keyframe of its root segment.
void LoopCloser::buildGraph(const PlaceMap& map) {
  graph_.clear();
  std::fill(node_of_slot_.begin(), node_of_slot_.end(), -1);
  for (int slot = 0; slot < map.capacity(); ++slot) {
    const PlaceKeyframe& k = map.keyframe(slot);
    if (!k.alive) continue;
    const int node = graph_.addNode(k.T_w_k, false);
    node_of_slot_[static_cast<std::size_t>(slot)] = node;
    slot_of_node_[static_cast<std::size_t>(node)] = slot;
  }
  for (int32_t s = 0; s < map.segments(); ++s) {
    if (findRoot(s) != s) continue;
    const int oldest = segmentEnd(map, s, /*oldest=*/true);
    if (oldest >= 0) graph_.setFixed(node_of_slot_[static_cast<std::size_t>(oldest)], true);
  }
  for (int slot = 0; slot < map.capacity(); ++slot) {
    const PlaceKeyframe& k = map.keyframe(slot);
    if (!k.alive || k.previous < 0) continue;
    const SE3 T_a_b = map.keyframe(k.previous).T_o_k.inverse() * k.T_o_k;
    graph_.addEdge(node_of_slot_[static_cast<std::size_t>(k.previous)], node_of_slot_[static_cast<std::size_t>(slot)],
                   T_a_b, odometrySigma(T_a_b));
  }
  for (int i = 0; i < loop_count_; ++i) {
    const LoopEdge& e = loops_[static_cast<std::size_t>(i)];
    const int a = slotOfId(map, e.a), b = slotOfId(map, e.b);
    if (a >= 0 && b >= 0)
      graph_.addEdge(node_of_slot_[static_cast<std::size_t>(a)], node_of_slot_[static_cast<std::size_t>(b)], e.T_a_b,
                     e.sigma);
  }
}

}  // namespace mcslam
