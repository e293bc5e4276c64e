#include "mcslam/places/loop_correction.hpp"

#include <algorithm>
#include <numeric>

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

LoopCorrection::LoopCorrection(int max_keyframes, int max_loops)
    : graph_(max_keyframes, 2 * max_keyframes + max_loops),
      node_of_slot_(static_cast<std::size_t>(max_keyframes), -1),
      id_of_node_(static_cast<std::size_t>(max_keyframes), -1),
      nodes_by_id_(static_cast<std::size_t>(max_keyframes), -1),
      newest_node_(PlaceMap::kMaxSegments, -1),
      newest_pose_before_(PlaceMap::kMaxSegments),
      segment_delta_(PlaceMap::kMaxSegments) {
  solve_.graph = &graph_;
}

int LoopCorrection::nodeOfId(int64_t id, int nodes) const {
  const auto end = nodes_by_id_.begin() + nodes;
  const auto it = std::lower_bound(nodes_by_id_.begin(), end, id, [this](int32_t node, int64_t value) {
    return id_of_node_[static_cast<std::size_t>(node)] < value;
  });
  return it != end && id_of_node_[static_cast<std::size_t>(*it)] == id ? *it : -1;
}

void LoopCorrection::addLoops(std::span<const LoopEdge> loops, int nodes) {
  const auto end = nodes_by_id_.begin() + nodes;
  std::iota(nodes_by_id_.begin(), end, 0);
  std::sort(nodes_by_id_.begin(), end, [this](int32_t a, int32_t b) {
    return id_of_node_[static_cast<std::size_t>(a)] < id_of_node_[static_cast<std::size_t>(b)];
  });
  for (const LoopEdge& e : loops) {
    const int a = nodeOfId(e.a, nodes), b = nodeOfId(e.b, nodes);
    if (a >= 0 && b >= 0) graph_.addEdge(a, b, e.T_a_b, e.sigma);
  }
}

void LoopCorrection::start(const PlaceMap& map, std::span<const LoopEdge> loops,
                           std::span<const int32_t> root_of_segment) {
  graph_.clear();
  std::fill(node_of_slot_.begin(), node_of_slot_.end(), -1);
  std::fill(newest_node_.begin(), newest_node_.end(), -1);
  for (int slot = 0; slot < map.capacity(); ++slot) {
    const PlaceKeyframe& k = map.keyframe(slot);
    if (!k.alive) continue;
    const int node = graph_.addNode(k.T_w_k, false);
    node_of_slot_[static_cast<std::size_t>(slot)] = node;
    id_of_node_[static_cast<std::size_t>(node)] = k.id;
    if (k.next < 0) {
      newest_node_[static_cast<std::size_t>(k.segment)] = node;
      newest_pose_before_[static_cast<std::size_t>(k.segment)] = k.T_w_k;
    }
    if (k.previous < 0 && root_of_segment[static_cast<std::size_t>(k.segment)] == k.segment)
      graph_.setFixed(node, true);
  }
  for (int slot = 0; slot < map.capacity(); ++slot) {
    const PlaceKeyframe& k = map.keyframe(slot);
    if (!k.alive || k.previous < 0) continue;
    const SE3 T_a_b = map.keyframe(k.previous).T_o_k.inverse() * k.T_o_k;
    graph_.addEdge(node_of_slot_[static_cast<std::size_t>(k.previous)], node_of_slot_[static_cast<std::size_t>(slot)],
                   T_a_b, odometrySigma(T_a_b));
  }
  addLoops(loops, graph_.nodes());
  graph_reshapes_ = map.reshapes();
  graph_segments_ = map.segments();
  graph_next_id_ = map.nextId();
  task_.start(solve_);
}

LoopCorrection::Outcome LoopCorrection::take(PlaceMap& map, bool wait) {
  if (!task_.running() || (!wait && !task_.ready())) return Outcome::None;
  task_.collect();
  if (map.reshapes() != graph_reshapes_) return Outcome::Stale;
  apply(map);
  return Outcome::Applied;
}

int LoopCorrection::newestNode(int32_t segment) const {
  return segment < graph_segments_ ? newest_node_[static_cast<std::size_t>(segment)] : -1;
}

void LoopCorrection::apply(PlaceMap& map) {
  for (int32_t s = 0; s < map.segments(); ++s) {
    const int newest = newestNode(s);
    if (newest >= 0)
      segment_delta_[static_cast<std::size_t>(s)] =
          graph_.pose(newest) * newest_pose_before_[static_cast<std::size_t>(s)].inverse();
  }
  // A segment with no keyframe in the graph (begun during the solve, or without keyframes) moves with the nearest
  // segment up the chain it continues that has one; a reused segment may continue one numbered after it.
  for (int32_t s = 0; s < map.segments(); ++s) {
    if (newestNode(s) >= 0) continue;
    int32_t parent = map.continuesFrom(s);
    for (int hops = 0; parent >= 0 && newestNode(parent) < 0 && hops < PlaceMap::kMaxSegments; ++hops)
      parent = map.continuesFrom(parent);
    segment_delta_[static_cast<std::size_t>(s)] =
        parent >= 0 && newestNode(parent) >= 0 ? segment_delta_[static_cast<std::size_t>(parent)] : SE3();
  }
  for (int32_t s = 0; s < map.segments(); ++s)
    map.setSegmentPose(s, segment_delta_[static_cast<std::size_t>(s)] * map.segmentPose(s));
  for (int slot = 0; slot < map.capacity(); ++slot) {
    const PlaceKeyframe& k = map.keyframe(slot);
    if (!k.alive) continue;
    const int node = node_of_slot_[static_cast<std::size_t>(slot)];
    if (k.id < graph_next_id_ && node >= 0 && id_of_node_[static_cast<std::size_t>(node)] == k.id) {
      map.setKeyframePose(slot, graph_.pose(node));
    } else {
      map.setKeyframePose(slot, segment_delta_[static_cast<std::size_t>(k.segment)] * k.T_w_k);
    }
  }
}

}  // namespace mcslam
