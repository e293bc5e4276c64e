#pragma once
// Visual odometry for a generalized camera (paper sections IV-B, IV-C, V): initialization, tracking
// of every frame against the local map, keyframes, new landmarks from multi-view features and from
// rays of different cameras and times, and the sliding-window back-end. Works for one camera, for
// overlapping and for non-overlapping rigs alike. All memory is allocated at construction.
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <span>
#include <vector>

#include "mcslam/core/background_task.hpp"
#include "mcslam/odometry/loss_clock.hpp"
#include "mcslam/odometry/map.hpp"
#include "mcslam/odometry/map_seed.hpp"
#include "mcslam/odometry/odometry_options.hpp"
#include "mcslam/odometry/pose_estimate.hpp"
#include "mcslam/odometry/rig_state.hpp"

namespace mcslam {

// Counters for the stats file.
struct OdometryStats {
  uint64_t frames = 0;
  uint64_t tracking = 0;
  uint64_t not_initialized = 0;
  uint64_t lost = 0;
  uint64_t initializations = 0;
  uint64_t keyframes = 0;
  uint64_t recoveries = 0;       // frames tracked only through the descriptor fallback
  uint64_t relocalizations = 0;  // lost frames the place map found (relocalize())
  uint64_t backend_solves = 0;
  uint64_t extrinsic_reestimations = 0;  // cameras whose extrinsic the per-camera check replaced
  uint64_t stamps_not_increasing = 0;    // frames stamped at or before the frame before them (LossClock)
  double last_backend_ms = 0;
  // Metric scale of a rig without overlap (started up to scale), or of a roughly metric map: frame from which the
  // map is metric (-1: not yet, or the map started metric), the window's scale estimates and the rescalings they
  // caused.
  int64_t scale_converged_frame = -1;
  uint64_t scale_estimates = 0;
  uint64_t scale_rescales = 0;
  double last_scale = 1;                   // factor of the last window estimate
  double last_scale_sigma = INFINITY;      // its sigma(s) / s
  double combined_scale_sigma = INFINITY;  // of the estimates combined (ScaleFilter)
};

// Milliseconds spent in the stages of the last processed frame.
struct OdometryTiming {
  double tracking_ms = 0;  // pose estimation and keyframe decision
  double mapping_ms = 0;   // keyframe insertion and new landmarks (those made on the back-end thread: in backend_ms
                           // of the next frame, as far as it waits for them)
  double backend_ms = 0;   // sliding-window optimization
};

class ExtrinsicCheck;
class InitializationAttempt;
class Initializer;
class LocalMapper;
class ScaleSupervisor;
class TemporalTriangulator;
class Tracker;
class WindowBridge;

class Odometry {
 public:
  Odometry(const Rig& rig, const OdometryOptions& options, int max_features_per_camera);
  ~Odometry();
  Odometry(const Odometry&) = delete;
  Odometry& operator=(const Odometry&) = delete;

  // Estimates the pose of one rig frame whose features (and multi-view features) are computed.
  void process(const FrameFeatures& frame, uint64_t frame_index, PoseEstimate& out);
  // Completes the back-end work of the last keyframe: waits for its solve, applies it, then finishKeyframe().
  // process() does it first thing; call it after the last frame, before reading the map's final keyframes.
  void flush();
  // A keyframe of a map that applies each solve before the next frame (one camera's maps, maps started up to
  // scale or roughly metric, and any map when backend_apply_after_frames is 1) leaves its new landmarks to the back-end
  // thread, before its solve: the next frame tracks on the same map as if they had been made at once, and the
  // keyframe's frame no longer pays for them. The job writes the map, so it starts only once the frame has no more use
  // for the new landmarks: the caller says when (the pipeline, after place memory); flush() and the next process()
  // start it otherwise. From then until the next process() or flush(), map() may be read only for what the job
  // does not write: keyframes' poses, stamps and ids.
  void startDeferredMapping();

  // The frame was lost and place memory found it at T_w_b (this odometry's frame) with the place map's points
  // matched to its keypoints: the local map starts again there, from those points and the frame's own multi-view
  // features, in the same frame and unit. `out` becomes the frame's tracked estimate.
  void relocalize(const FrameFeatures& frame, uint64_t frame_index, const SE3& T_w_b, std::span<const MapSeed> seeds,
                  PoseEstimate& out);
  // Keyframes (slots) that became final in the last process() or relocalize(): solved by the back-end and culled,
  // or the first keyframes of a new map. Valid until the next call.
  std::span<const int32_t> settledKeyframes() const {
    return {settled_.data(), static_cast<std::size_t>(settled_count_)};
  }

  // The map's unit changed (a rig without overlap found or followed its scale): positions p became
  // center + s (p - center). Those of the last process(), in order; valid until the next call. The motion found in
  // the wrong unit is that of the keyframes from frame `from_frame` on (ScaleSupervisor::Rescale).
  struct Rescale {
    double s = 1;
    Vec3 center = Vec3::Zero();
    uint64_t from_frame = 0;
  };
  std::span<const Rescale> rescales() const { return {rescales_.data(), static_cast<std::size_t>(rescale_count_)}; }

  const OdometryStats& stats() const { return stats_; }
  const OdometryTiming& timing() const { return timing_; }
  const Map& map() const { return map_; }
  // The rig with the extrinsics the back-end refined (the calibration when refinement is off).
  Rig refinedRig() const;
  // The rig state as of the end of the last frame (tracking takes it at the start of the next one): with
  // refinement on, the extrinsics as of the last applied solve or per-camera check. A view for the call: a
  // consumer keeps a copy (RigState::follow()).
  const RigState& rigState() const;
  const Rig& trackingRig() const { return rigState().rig(); }
  bool initialized() const { return initialized_; }
  // False while a map started up to scale (rig without overlap) waits for its window to fix the scale: poses
  // until then have an arbitrary unit. True for a metric start, a roughly metric one (no estimate runs for it) and
  // for one camera (whose scale never is).
  bool scaleConverged() const { return rigState().scaleConverged(); }
  // Relative standard deviation of the map's unit now (ScaleSupervisor::unitSigma; a fixed 25% for a roughly
  // metric map): how far the length of a motion tracked in this map can be off while its direction is not.
  double unitSigma() const;
  // Heap allocations made so far on the back-end thread and the scale estimate's (0 when they run inline).
  uint64_t backendThreadAllocations() const;
  // Set by the process() that started a map from two frames, until the next process() of an uninitialized frame:
  // the reference frame and the frame the map started at (both -1 otherwise), and their poses in this odometry's
  // frame. The frames between them have no estimate of their own, and the start frame was published as not
  // initialized (its attempt is taken at the next frame, the first tracked).
  struct InitializationSpan {
    int64_t reference = -1;
    int64_t start = -1;
    SE3 T_w_reference;
    SE3 T_w_start;
    bool metric = true;  // the unit of both poses as the map started (PoseEstimate's flags)
    bool roughly_metric = false;
  };
  const InitializationSpan& lastInitialization() const { return last_init_; }

 private:
  // The initialize state: a map from one frame (enough metric multi-view features) or from two, the second being
  // the last frame, whose attempt ran beside this one (InitializationAttempt). True when the map started from the
  // last frame: this frame is still to be tracked on it.
  bool initialize(const FrameFeatures& frame, uint64_t frame_index, PoseEstimate& out);
  bool startFromAttempt();  // the last frame's attempt succeeded and its map started
  int initializeFromOneFrame(const FrameFeatures& frame, uint64_t frame_index);  // keyframe slot, -1: not yet
  int initializeFromTwoFrames(const FrameFeatures& frame, uint64_t frame_index, const SE3& T_ref_cur);
  // The unit of a map started at `frame`: metric when the frame holds enough metric multi-view points, uncertain
  // when its cameras overlap but see their common points too far for that, up to scale without `overlap`.
  ScaleStatus startScale(const FrameFeatures& frame, bool overlap) const;
  bool seesMetricPoints(const FrameFeatures& frame) const;
  int metricMultiView(const FrameFeatures& frame) const;  // Initializer::metricMultiView with this rig and options
  // A keyframe of a map whose unit is uncertain sees enough metric points: from now on the map is metric.
  void unitBecomesMetric(const FrameFeatures& frame, uint64_t frame_index);
  // The map starts at keyframe `kf_new` of frame `frame_index`: the track state.
  void startMap(int kf_new, uint64_t frame_index, ScaleStatus scale, bool new_map = true);
  // New points across time and when solves are applied, for a map whose unit rests on its window or not.
  void restUnitOnWindow(bool on_window);
  void publishStart(PoseEstimate& out);       // the frame the map started at is its first keyframe, tracked
  void publishUnit(PoseEstimate& out) const;  // the pose's unit flags, from the rig state as it is now
  void processFrame(const FrameFeatures& frame, uint64_t frame_index, PoseEstimate& out);
  // The frame could not be tracked: the motion model carries on; a loss that lasts drops the map.
  void lose(uint64_t frame_index, int inliers, PoseEstimate& out);
  void noteStampNotIncreasing(const FrameFeatures& frame, uint64_t frame_index);
  // A keyframe of the tracked frame: its landmarks, new points, and its back-end solve started.
  void makeKeyframe(const FrameFeatures& frame, uint64_t frame_index, const SE3& T_w_b, int inliers, PoseEstimate& out);
  // The keyframe's new points and the start of its solve, now (mapNow) or on the back-end thread later.
  void mapNow(int slot, uint64_t frame_index, int inliers, std::chrono::steady_clock::time_point map_start);
  void deferMapping(int slot);
  bool mappingDeferrable() const;
  // New landmarks across time for keyframe `slot` (TemporalTriangulator); returns how many.
  int triangulateNew(int slot);
  void finishKeyframe(int slot);
  // At the start of a frame: the pending solve is applied when it is due (backend_apply_after_frames), or at once
  // when this frame will not simply be tracked against the map.
  void applyDueSolve();
  void noteSettled(int slot);  // culling and the state that follows the (optimized) keyframe pose
  void resetMap();
  void clearMap();  // the map, the mapper's pending work and the window
  // At a settled keyframe of a map started up to scale: the map, the window and the motion model take the unit
  // the scale supervisor finds.
  void estimateScale();

  // New landmarks for a keyframe, run on the back-end thread before its solve (startDeferredMapping()).
  struct KeyframeMapping final : BackgroundJob {
    void run() override;
    Odometry* odometry = nullptr;
    int slot = -1;
  };

  OdometryOptions options_;
  Map map_;
  std::unique_ptr<Tracker> tracker_;
  std::unique_ptr<Initializer> initializer_;
  std::unique_ptr<InitializationAttempt> attempt_;  // after the initializer: its job uses it
  std::unique_ptr<LocalMapper> mapper_;
  std::unique_ptr<TemporalTriangulator> triangulator_;
  std::unique_ptr<WindowBridge> bridge_;
  std::unique_ptr<ExtrinsicCheck> extrinsic_check_;  // with refinement on and several cameras
  std::unique_ptr<ScaleSupervisor> scale_;

  bool initialized_ = false;
  SE3 anchor_;                  // pose given to the next initialization (continuity after a loss)
  int pending_keyframe_ = -1;   // keyframe whose back-end solve has not been applied yet
  int pending_frames_ = 0;      // frames begun since that solve started
  int apply_after_frames_ = 1;  // of this map (OdometryOptions::backend_apply_after_frames where it applies)
  KeyframeMapping mapping_;
  bool mapping_due_ = false;  // pending_keyframe_'s new landmarks wait for startDeferredMapping()
  int lost_frames_ = 0;
  LossClock loss_clock_;
  std::array<int32_t, 4> settled_{};
  int settled_count_ = 0;
  std::array<Rescale, 4> rescales_{};
  int rescale_count_ = 0;
  InitializationSpan last_init_;
  uint64_t frame_index_ = 0;  // of the frame being processed
  OdometryStats stats_;
  OdometryTiming timing_;
};

}  // namespace mcslam
