#pragma once
// Per-camera extrinsic check, when extrinsics are refined. A calibration error of a degree moves a camera's
// projections by ~10 px, past the tracking's inlier gate: its observations never reach the back-end that would
// refine the extrinsic. So when one camera's inliers collapse against the others', the body pose tracked from
// the rest places the local map in the frame; the map is matched into that camera alone with a wide window and
// the camera's pose is solved alone (P3P RANSAC and refinement through its lens model). The body-from-camera
// implied by several frames, when they agree, becomes the estimate tracking and the back-end start from (the
// calibration stays the back-end's prior). Every threshold is in pixels against the tracking's inlier gate.
// The map's live list must be fresh (the odometry refreshes it before tracking).
#include <memory>
#include <vector>

#include "mcslam/features/octave_scales.hpp"
#include "mcslam/geometry/absolute_pose_ransac.hpp"
#include "mcslam/odometry/odometry_options.hpp"
#include "mcslam/odometry/projection_search.hpp"

namespace mcslam {

class ExtrinsicCheck {
 public:
  // rig: the calibration (its lens models; nothing of it is kept).
  ExtrinsicCheck(const Rig& rig, const OdometryOptions& options, int max_features_per_camera);
  ~ExtrinsicCheck();

  // After frame `frame` was tracked at T_w_b with inlier matches `matches` (`search` prepared for the frame),
  // with the current extrinsics `rig` (a view for the call). Returns the camera whose extrinsic estimate should
  // become T_b_c, or -1.
  int check(const Map& map, ProjectionSearch& search, const Rig& rig, const FrameFeatures& frame,
            const FrameMatches& matches, const SE3& T_w_b, SE3& T_b_c);
  void reset();  // the map was dropped: its samples with it

  // Frames whose implied extrinsics must agree before one is adopted.
  static constexpr int kSamples = 9;

 private:
  struct Sample {
    SE3 T_b_c;
    double depth = 0;  // median depth of the camera's inliers, metres
  };
  int suspectCamera(const FrameFeatures& frame, const FrameMatches& matches);
  bool sample(int cam, const Map& map, ProjectionSearch& search, const Rig& rig, const FrameFeatures& frame,
              const SE3& T_w_b, Sample& out);
  bool decide(int cam, const Rig& rig, SE3& T_b_c);
  // RMS pixel distance, over a few points of camera `cam`'s image at `depth`, between seeing them through
  // extrinsic a and through extrinsic b (infinite when one does not project).
  double pixelShift(const CameraModel& model, const SE3& a, const SE3& b, double depth) const;

  OdometryOptions options_;
  OctaveScales octave_scale_{options_.scale_factor};
  double gate_px_;  // the tracking's inlier gate at octave 0: sqrt(chi-square 2 dof, 95%) sigmas of 1 px
  std::vector<std::unique_ptr<AbsolutePoseRansac>> ransac_;  // per camera: that camera alone as a rig
  FrameMatches wide_;
  std::vector<PoseObservation> obs_;
  std::vector<double> scratch_;
  std::vector<int> inliers_;                  // per camera, this frame
  std::vector<std::vector<Sample>> samples_;  // per camera, consecutive frames in which it was suspect
  std::vector<int> sample_count_;
};

}  // namespace mcslam
