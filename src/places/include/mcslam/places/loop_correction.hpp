#pragma once
// The place map's correction after a loop closure: a pose graph over every place keyframe (consecutive keyframes
// of a segment joined by the odometry's relative poses, and the loops), solved on a thread of its own so that no
// frame waits for it, and taken into the map at a frame boundary. The keyframes in the graph take its solution;
// each segment's frame follows its newest keyframe in the graph (the odometry goes on from where the map now puts
// it), and so do the keyframes made during the solve, which were placed through that frame; a segment begun during
// the solve (or empty when it began) moves with the one it continues. In a map whose unit is not metric the graph
// is over similarities: each keyframe also takes a scale, its points grow or shrink with it, and so does the unit of
// its segment's odometry in the world. Fixed memory: the graph and every buffer are sized at construction.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "mcslam/backend/pose_graph.hpp"
#include "mcslam/core/background_task.hpp"
#include "mcslam/places/place_map.hpp"

namespace mcslam {

// A loop: keyframe b seen from keyframe a, with the uncertainty of the verification. In a map whose unit is not
// metric (a Sim(3) loop), b's surroundings are `scale` times as large in a's unit as in b's own, and the relative
// pose is in a's unit, both units the keyframes' odometry's (PlaceKeyframe::unit undone); rigid loops are in the
// world's unit (metres, or the unit a rig without overlap had when it closed them: LoopCloser::followRescale keeps
// them in step with its rescales) with a scale of 1.
struct LoopEdge {
  int64_t a = -1, b = -1;  // place keyframe ids
  SE3 T_a_b;
  Vec6 sigma = Vec6::Ones();
  double scale = 1.0;
  double sigma_log_scale = 0.0;  // 0: a metric loop, whose scale is exact
};

class LoopCorrection {
 public:
  // Starts the solving thread; its destructor lets a solve finish. `similarity`: the map's unit is not metric (one
  // camera), so the graph is over Sim(3) poses and its loops measure a scale; SE(3) otherwise.
  LoopCorrection(int max_keyframes, int max_loops, bool similarity = false);
  LoopCorrection(const LoopCorrection&) = delete;
  LoopCorrection& operator=(const LoopCorrection&) = delete;

  // Builds the graph of `map` with `loops` and starts solving it. Each set of segments that loops joined is held
  // at the oldest keyframe of its root segment (`root_of_segment`, one per segment of the map). Only when
  // running() is false.
  void start(const PlaceMap& map, std::span<const LoopEdge> loops, std::span<const int32_t> root_of_segment);
  bool running() const { return task_.running(); }
  bool similarity() const { return similar_ != nullptr; }

  enum class Outcome {
    None,     // nothing solved to take (none started, or, without `wait`, not finished)
    Applied,  // the map took the solution
    Stale,    // a segment was moved or rescaled during the solve (PlaceMap::reshapes): start again
  };
  // At a frame boundary. With `wait`, waits for a solve in flight.
  // `camera_centers`: each camera's centre in the body frame, about which a keyframe's points scale in a Sim(3)
  // correction (PlaceMap::scaleKeyframe).
  Outcome take(PlaceMap& map, bool wait, std::span<const Vec3> camera_centers = {});
  double lastSolveMs() const { return task_.lastMilliseconds(); }
  const backend::PoseGraphSummary& lastSummary() const { return solve_.summary; }  // of the solve last taken
  uint64_t threadAllocations() const { return task_.allocations(); }  // by the solving thread; any thread may ask

 private:
  struct GraphSolve final : BackgroundJob {
    void run() override { summary = rigid ? rigid->optimize() : similar->optimize(); }
    backend::PoseGraph* rigid = nullptr;
    backend::SimilarityPoseGraph* similar = nullptr;
    backend::PoseGraphSummary summary;
  };

  template <class Graph>
  void build(Graph& graph, const PlaceMap& map, std::span<const LoopEdge> loops,
             std::span<const int32_t> root_of_segment);
  template <class Graph>
  void apply(const Graph& graph, PlaceMap& map, std::span<const Vec3> camera_centers);
  int newestNode(int32_t segment) const;  // the segment's newest keyframe in the graph being solved, or -1
  template <class Graph>
  void addLoops(Graph& graph, const PlaceMap& map, std::span<const LoopEdge> loops, int nodes);
  int nodeOfId(int64_t id, int nodes) const;  // -1 when no node has it (the keyframe was let go)

  std::unique_ptr<backend::PoseGraph> rigid_;              // a metric map's graph, or
  std::unique_ptr<backend::SimilarityPoseGraph> similar_;  // the graph of a map whose unit drifts
  GraphSolve solve_;
  std::vector<int32_t> node_of_slot_;
  // What the graph being solved was built from: each node's keyframe id, each segment's newest node and its pose
  // then, the map's reshape count, segment count and next keyframe id.
  std::vector<int64_t> id_of_node_;
  std::vector<int32_t> slot_of_node_;
  std::vector<int32_t> nodes_by_id_;  // scratch of start(): the nodes in increasing keyframe id
  std::vector<int32_t> newest_node_;
  std::vector<SE3> newest_pose_before_;
  std::vector<Sim3> segment_delta_;  // scratch of apply(): how each segment's frame moved
  uint64_t graph_reshapes_ = 0;
  int graph_segments_ = 0;
  int64_t graph_next_id_ = 0;
  BackgroundTask task_;  // last: stops before the graph goes
};

}  // namespace mcslam
