#pragma once
// Scale supervision of a map that a rig without overlap started up to scale: at every settled keyframe whose
// back-end window turned, the window's metric scale is estimated (ScaleEstimator), the estimates are combined
// (ScaleFilter), and the supervisor says when the map must take a new unit: when the combined estimate is certain
// enough over enough rotation (the scale has converged) or significantly off. The caller applies the rescale to
// the map, the window and the motion model. Owns the estimator and the filter; the map and the rig state are
// handed in for each call. All memory is allocated at construction.
#include <cstdint>
#include <memory>

#include "mcslam/odometry/map.hpp"
#include "mcslam/odometry/odometry_options.hpp"
#include "mcslam/odometry/rig_state.hpp"

namespace mcslam {

class ScaleEstimator;
class ScaleFilter;
struct OdometryStats;

class ScaleSupervisor {
 public:
  // Nothing to supervise for one camera (its scale is never observable).
  ScaleSupervisor(const Rig& rig, const OdometryOptions& options, int max_features_per_camera);
  ~ScaleSupervisor();

  // A new map starts, up to scale (`unscaled`) or metric; what the filter knew goes with the old one.
  void start(bool unscaled);

  struct Rescale {
    bool apply = false;  // multiply positions about `center` by `s`
    double s = 1;
    Vec3 center = Vec3::Zero();
    bool converged = false;  // the first rescale of a certain estimate: the map is metric from now on
  };
  // After keyframe settling: an estimate over the map's newest keyframes, with the extrinsics of `rig`. Updates the
  // scale counters of `stats`.
  Rescale onKeyframe(const Map& map, const RigState& rig, double rotation_travelled, uint64_t frame_index,
                     OdometryStats& stats);

 private:
  // Largest rotation (rad) of a back-end window keyframe from the window's oldest.
  static double windowTurn(const Map& map);

  OdometryOptions options_;
  std::unique_ptr<ScaleEstimator> estimator_;  // null for one camera
  std::unique_ptr<ScaleFilter> filter_;
  bool unscaled_start_ = false;
};

}  // namespace mcslam
