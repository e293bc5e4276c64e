#include "mcslam/places/loop_correction.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "mcslam/places/loop_scale.hpp"

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

// The odometry's relative pose as a square-root information, with its length `unit_sigma` (relative) less certain
// than its direction: tracked in a map whose unit was still being found, or drifts, it knows where it went better
// than how far. The residual's translation is in b's frame, where the motion's direction is R_ab^T t_ab.
Mat6 odometrySqrtInformation(const SE3& T_a_b, double unit_sigma) {
  const Vec6 sigma = odometrySigma(T_a_b);
  Mat6 W = Mat6::Zero();
  W.diagonal() = sigma.cwiseInverse();
  const double d = T_a_b.t.norm();
  if (unit_sigma > 0 && d > 0) {
    const Vec3 along = T_a_b.R.transpose() * T_a_b.t / d;
    const Mat3 P = along * along.transpose();
    const double sigma_across = sigma[0];  // the same in every direction
    const double sigma_along = std::hypot(sigma_across, unit_sigma * d);
    W.topLeftCorner<3, 3>() = (Mat3::Identity() - P) / sigma_across + P / sigma_along;
  }
  return W;
}

Vec7 withScale(const Vec6& sigma, double log_scale_sigma) {
  Vec7 s;
  s << sigma, log_scale_sigma;
  return s;
}

// Graph nodes and edges of either kind, from the map's SE(3) poses and the odometry's units.
template <class Pose>
struct Edges;

template <>
struct Edges<SE3> {
  static SE3 node(const SE3& T_w_k) { return T_w_k; }
  static void odometry(backend::PoseGraph& g, int a, int b, const PlaceKeyframe& ka, const PlaceKeyframe& kb) {
    const SE3 T_a_b = ka.T_o_k.inverse() * kb.T_o_k;
    g.addEdge(a, b, T_a_b, odometrySqrtInformation(T_a_b, kb.unit_sigma));
  }
  static void loop(backend::PoseGraph& g, int a, int b, const LoopEdge& e, const PlaceKeyframe&, const PlaceKeyframe&) {
    g.addEdge(a, b, e.T_a_b, e.sigma);
  }
};

template <>
struct Edges<Sim3> {
  static Sim3 node(const SE3& T_w_k) { return Sim3(T_w_k); }
  // The odometry's motion from a to b in a's world unit; b's own unit is `kb.unit` (world per odometry).
  static void odometry(backend::SimilarityPoseGraph& g, int a, int b, const PlaceKeyframe& ka,
                       const PlaceKeyframe& kb) {
    SE3 T_a_b = ka.T_o_k.inverse() * kb.T_o_k;
    T_a_b.t *= ka.unit;
    g.addEdge(a, b, Sim3(T_a_b, ka.unit / kb.unit), withScale(odometrySigma(T_a_b), kOdometryLogScaleSigma));
  }
  // The loop in the keyframes' current units (those of the graph's nodes).
  static void loop(backend::SimilarityPoseGraph& g, int a, int b, const LoopEdge& e, const PlaceKeyframe& ka,
                   const PlaceKeyframe& kb) {
    SE3 T_a_b = e.T_a_b;
    T_a_b.t *= ka.unit;
    Vec6 sigma = e.sigma;
    sigma.head<3>() *= ka.unit;
    g.addEdge(a, b, Sim3(T_a_b, e.scale * ka.unit / kb.unit),
              withScale(sigma, std::max(e.sigma_log_scale, kLoopLogScaleSigmaFloor)));
  }
};

}  // namespace

LoopCorrection::LoopCorrection(int max_keyframes, int max_loops, bool similarity)
    : node_of_slot_(static_cast<std::size_t>(max_keyframes), -1),
      id_of_node_(static_cast<std::size_t>(max_keyframes), -1),
      slot_of_node_(static_cast<std::size_t>(max_keyframes), -1),
      nodes_by_id_(static_cast<std::size_t>(max_keyframes), -1),
      newest_node_(PlaceMap::kMaxSegments, -1),
      newest_pose_before_(PlaceMap::kMaxSegments),
      segment_delta_(PlaceMap::kMaxSegments) {
  const int max_edges = 2 * max_keyframes + max_loops;
  if (similarity) {
    similar_ = std::make_unique<backend::SimilarityPoseGraph>(max_keyframes, max_edges);
    solve_.similar = similar_.get();
  } else {
    rigid_ = std::make_unique<backend::PoseGraph>(max_keyframes, max_edges);
    solve_.rigid = rigid_.get();
  }
}

int LoopCorrection::nodeOfId(int64_t id, int nodes) const {
  const auto end = nodes_by_id_.begin() + nodes;
  const auto it = std::lower_bound(nodes_by_id_.begin(), end, id, [this](int32_t node, int64_t value) {
    return id_of_node_[static_cast<std::size_t>(node)] < value;
  });
  return it != end && id_of_node_[static_cast<std::size_t>(*it)] == id ? *it : -1;
}

template <class Graph>
void LoopCorrection::addLoops(Graph& graph, const PlaceMap& map, std::span<const LoopEdge> loops, int nodes) {
  using Pose = std::decay_t<decltype(graph.pose(0))>;
  const auto end = nodes_by_id_.begin() + nodes;
  std::iota(nodes_by_id_.begin(), end, 0);
  std::sort(nodes_by_id_.begin(), end, [this](int32_t a, int32_t b) {
    return id_of_node_[static_cast<std::size_t>(a)] < id_of_node_[static_cast<std::size_t>(b)];
  });
  for (const LoopEdge& e : loops) {
    const int a = nodeOfId(e.a, nodes), b = nodeOfId(e.b, nodes);
    if (a >= 0 && b >= 0)
      Edges<Pose>::loop(graph, a, b, e, map.keyframe(slot_of_node_[static_cast<std::size_t>(a)]),
                        map.keyframe(slot_of_node_[static_cast<std::size_t>(b)]));
  }
}

void LoopCorrection::start(const PlaceMap& map, std::span<const LoopEdge> loops,
                           std::span<const int32_t> root_of_segment) {
  if (rigid_) build(*rigid_, map, loops, root_of_segment);
  if (similar_) build(*similar_, map, loops, root_of_segment);
  graph_reshapes_ = map.reshapes();
  graph_segments_ = map.segments();
  graph_next_id_ = map.nextId();
  task_.start(solve_);
}

template <class Graph>
void LoopCorrection::build(Graph& graph, const PlaceMap& map, std::span<const LoopEdge> loops,
                           std::span<const int32_t> root_of_segment) {
  using Pose = std::decay_t<decltype(graph.pose(0))>;
  graph.clear();
  std::fill(node_of_slot_.begin(), node_of_slot_.end(), -1);
  std::fill(newest_node_.begin(), newest_node_.end(), -1);
  for (int slot = 0; slot < map.capacity(); ++slot) {
    const PlaceKeyframe& k = map.keyframe(slot);
    if (!k.alive) continue;
    const int node = graph.addNode(Edges<Pose>::node(k.T_w_k), false);
    node_of_slot_[static_cast<std::size_t>(slot)] = node;
    slot_of_node_[static_cast<std::size_t>(node)] = slot;
    id_of_node_[static_cast<std::size_t>(node)] = k.id;
    if (k.next < 0) {
      newest_node_[static_cast<std::size_t>(k.segment)] = node;
      newest_pose_before_[static_cast<std::size_t>(k.segment)] = k.T_w_k;
    }
    if (k.previous < 0 && root_of_segment[static_cast<std::size_t>(k.segment)] == k.segment) graph.setFixed(node, true);
  }
  for (int slot = 0; slot < map.capacity(); ++slot) {
    const PlaceKeyframe& k = map.keyframe(slot);
    if (!k.alive || k.previous < 0) continue;
    Edges<Pose>::odometry(graph, node_of_slot_[static_cast<std::size_t>(k.previous)],
                          node_of_slot_[static_cast<std::size_t>(slot)], map.keyframe(k.previous), k);
  }
  addLoops(graph, map, loops, graph.nodes());
}

LoopCorrection::Outcome LoopCorrection::take(PlaceMap& map, bool wait, std::span<const Vec3> camera_centers) {
  if (!task_.running() || (!wait && !task_.ready())) return Outcome::None;
  task_.collect();
  if (map.reshapes() != graph_reshapes_) return Outcome::Stale;
  if (rigid_) apply(*rigid_, map, camera_centers);
  if (similar_) apply(*similar_, map, camera_centers);
  return Outcome::Applied;
}

int LoopCorrection::newestNode(int32_t segment) const {
  return segment < graph_segments_ ? newest_node_[static_cast<std::size_t>(segment)] : -1;
}

template <class Graph>
void LoopCorrection::apply(const Graph& graph, PlaceMap& map, std::span<const Vec3> camera_centers) {
  using Pose = std::decay_t<decltype(graph.pose(0))>;
  for (int32_t s = 0; s < map.segments(); ++s) {
    const int newest = newestNode(s);
    if (newest >= 0)
      segment_delta_[static_cast<std::size_t>(s)] =
          Sim3(graph.pose(newest) * Edges<Pose>::node(newest_pose_before_[static_cast<std::size_t>(s)].inverse()));
  }
  // A segment with no keyframe in the graph (begun during the solve, or without keyframes) moves with the nearest
  // segment up the chain it continues that has one; a reused segment may continue one numbered after it.
  for (int32_t s = 0; s < map.segments(); ++s) {
    if (newestNode(s) >= 0) continue;
    int32_t parent = map.continuesFrom(s);
    for (int hops = 0; parent >= 0 && newestNode(parent) < 0 && hops < PlaceMap::kMaxSegments; ++hops)
      parent = map.continuesFrom(parent);
    segment_delta_[static_cast<std::size_t>(s)] =
        parent >= 0 && newestNode(parent) >= 0 ? segment_delta_[static_cast<std::size_t>(parent)] : Sim3();
  }
  // Rotations are made orthonormal again: each correction composes the segment's frame with the last one, and its
  // newest keyframe's pose with that frame, so a rounding error of the rotation would double with every correction.
  for (int32_t s = 0; s < map.segments(); ++s) {
    Sim3 moved = segment_delta_[static_cast<std::size_t>(s)] * map.segmentSimilarity(s);
    moved.normalize();
    map.setSegmentPose(s, moved.rigid());
    map.setSegmentScale(s, moved.s);
  }
  for (int slot = 0; slot < map.capacity(); ++slot) {
    const PlaceKeyframe& k = map.keyframe(slot);
    if (!k.alive) continue;
    const int node = node_of_slot_[static_cast<std::size_t>(slot)];
    const bool in_graph = k.id < graph_next_id_ && node >= 0 && id_of_node_[static_cast<std::size_t>(node)] == k.id;
    Sim3 moved =
        in_graph ? Sim3(graph.pose(node)) : segment_delta_[static_cast<std::size_t>(k.segment)] * Sim3(k.T_w_k);
    moved.normalize();
    map.setKeyframePose(slot, moved.rigid());
    if (moved.s != 1.0) map.scaleKeyframe(slot, moved.s, camera_centers);
  }
}

}  // namespace mcslam
