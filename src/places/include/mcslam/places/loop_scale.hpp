#pragma once
// The scale of a loop in a map whose unit is not metric: a keyframe recognized an older place, and the verified
// pose puts the older place's points in the keyframe's body frame, in the older place's unit. The keyframe's own
// points of the same keypoints are in its own unit: the ratio of their distances from the camera is the ratio of
// the two units. Robust (the median of the ratios), with the uncertainty of that median from their spread.
#include <Eigen/Core>
#include <span>
#include <vector>

#include "mcslam/calib/rig.hpp"
#include "mcslam/places/relocalizer.hpp"

namespace mcslam {

// A monocular odometry's unit drifts like its translation: about 1% from one keyframe to the next.
inline constexpr double kOdometryLogScaleSigma = 0.01;
// A loop's scale is measured from hundreds of point depths; no better than this, whatever their spread says.
inline constexpr double kLoopLogScaleSigmaFloor = 0.005;

struct LoopScale {
  bool ok = false;             // enough of the inliers have a point of the keyframe's own
  double scale = 1.0;          // the older place's unit over the keyframe's: its points are `scale` times as far
  double sigma_log_scale = 0;  // standard deviation of log(scale)
  int samples = 0;
};

// `own_points[cam * per_camera + kp]`: the keyframe's own point of that keypoint in its body frame, NaN where it has
// none. `T_w_b`: the verified pose; `scratch` is sized by the caller (fixed memory): at most its size of the
// inliers are used. `keyframe`: only the inliers of that place keyframe (slot, PlaceMatch::keyframe), or all (-1);
// `cam`: only those of that camera, or all (-1).
LoopScale loopScale(std::span<const PlaceMatch> inliers, std::span<const Eigen::Vector3f> own_points, int per_camera,
                    const SE3& T_w_b, const Rig& rig, std::vector<double>& scratch, int keyframe = -1, int cam = -1);

// A place made while the odometry's unit was uncertain (a rig without overlap, before its scale was found) has its
// points in the unit of then, which the later rescales of the whole map brought only near the metric one: a pose
// measured on them is off by as much as their depths are. Whether a loop can be measured on such a place is
// decided by the scale of the loop (`scale`, measured on the place's matches against the recognizing keyframe's own
// points):
enum class PlaceUnit {
  Known,       // the place's unit was known to kUncertainUnit when it was made, or agrees with the keyframe's
  Unmeasured,  // uncertain, and nothing to measure it with: the keyframe's own unit is uncertain, or too few points
  Other,       // its points are `scale.scale` times as far as the keyframe's own, beyond the measurement's error
};
inline constexpr double kUncertainUnit = 0.1;  // relative standard deviation of the unit
PlaceUnit placeUnit(double place_unit_sigma, double keyframe_unit_sigma, const LoopScale& scale);

}  // namespace mcslam
