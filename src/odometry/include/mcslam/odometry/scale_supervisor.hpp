#pragma once
// Scale supervision of a map that a rig without overlap started up to scale: at every settled keyframe whose
// back-end window turned, the window's metric scale is estimated (ScaleEstimator), the estimates are combined
// (ScaleFilter), and the supervisor says when the map must take a new unit: when the combined estimate is certain
// enough over enough rotation (the scale has converged) or significantly off. The caller applies the rescale to
// the map, the window and the motion model. An estimate costs several frames' tracking: it is copied out of the
// map at one settled keyframe, solved on the supervisor's thread (OdometryOptions::backend_thread; else at once)
// and taken at the next, whatever the thread's timing, so runs repeat exactly. Owns the estimator, the filter and
// the thread; the map and the rig state are handed in for each call. All memory is allocated at construction.
#include <cstdint>
#include <memory>

#include "mcslam/core/background_task.hpp"

#include "mcslam/odometry/map.hpp"
#include "mcslam/odometry/odometry_options.hpp"
#include "mcslam/odometry/rig_state.hpp"

namespace mcslam {

class ScaleEstimator;
struct ScaleEstimate;
class ScaleFilter;
struct OdometryStats;

class ScaleSupervisor {
 public:
  // Nothing to supervise for one camera (its scale is never observable).
  ScaleSupervisor(const Rig& rig, const OdometryOptions& options, int max_features_per_camera);
  ~ScaleSupervisor();

  // A new map starts, up to scale (`unscaled`) or metric; what the filter knew, and an estimate in flight, go with
  // the old one (the estimate is dropped when taken, without waiting for it here).
  void start(bool unscaled);

  struct Rescale {
    bool apply = false;  // multiply positions about `center` by `s`
    double s = 1;
    Vec3 center = Vec3::Zero();
    // The motion made in the unit found wrong: since the estimate window's oldest keyframe (its frame) once the
    // unit was known; all of it (0) while the unit was arbitrary.
    uint64_t from_frame = 0;
    bool converged = false;  // the first rescale of a certain estimate: the map is metric from now on
  };
  // At each settled keyframe (frame `frame_index`), in this order: takeEstimate() waits for the estimate
  // startEstimate() began at the last one (with OdometryOptions::repeatable false, takes it only if it is done) and
  // combines it (updating the scale counters of `stats`); the caller applies the rescale it returns; then
  // startEstimate() copies the window of the map's newest keyframes out, with the extrinsics of `rig`, and starts
  // its estimate when the window turned and none is in flight.
  Rescale takeEstimate(const Map& map, const RigState& rig, uint64_t frame_index, OdometryStats& stats);
  void startEstimate(const Map& map, const RigState& rig, double rotation_travelled, uint64_t frame_index);
  // Relative standard deviation of the map's unit as the estimates know it at keyframe `newest_id`: 0 for a rig
  // whose maps start metric (cameras that overlap: the unit is the metre from the start) and for one camera (its
  // graph carries the unit itself). For a rig without overlap: the combined estimate's sigma with the drift since,
  // at least the drift per keyframe, and 1 (the unit unknown) before any estimate; the drift per keyframe for a map
  // it started metric (from a place map's points after a loss), whose unit nothing follows.
  double unitSigma(int64_t newest_id) const;
  // Heap allocations made on the supervisor's thread so far (0 without one).
  uint64_t threadAllocations() const { return task_ ? task_->allocations() : 0; }

 private:
  struct EstimateJob;
  // Largest rotation (rad) of a back-end window keyframe from the window's oldest.
  static double windowTurn(const Map& map);
  void endEstimate();  // waits for the estimate in flight, if any; none is in flight after
  // Where the estimate's window started now: the back-end may have moved its oldest keyframe since the copy.
  static Vec3 centerNow(const Map& map, const ScaleEstimate& e);

  OdometryOptions options_;
  std::unique_ptr<ScaleEstimator> estimator_;  // null for one camera
  std::unique_ptr<ScaleFilter> filter_;
  std::unique_ptr<EstimateJob> job_;
  bool unscaled_start_ = false;
  bool ever_unscaled_ = false;            // some map of this rig started up to scale: its metric maps drift too
  bool in_flight_ = false;                // started and not taken
  bool stale_ = false;                    // the estimate in flight belongs to a map before start()
  std::unique_ptr<BackgroundTask> task_;  // last: stops before the estimator goes; null: estimates run at once
};

}  // namespace mcslam
