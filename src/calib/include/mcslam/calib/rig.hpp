#pragma once
// A rig of N >= 1 rigidly mounted cameras seen as one generalized camera (paper, section IV-B).
// The body frame is cam0 unless the calibration or the configuration says otherwise.
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "mcslam/calib/camera_model.hpp"

namespace mcslam {

// Plücker line of a keypoint in the body frame (paper eq. 3): unit direction d and moment
// m = c x d, with c the camera centre in the body frame.
struct PluckerRay {
  Vec3 d = Vec3::UnitZ();
  Vec3 m = Vec3::Zero();

  // Point of the line closest to the body origin.
  Vec3 closestPointToOrigin() const { return d.cross(m); }
};

struct RigCamera {
  std::string name;  // "cam0", ...
  CameraModel model;
  SE3 T_b_c;             // camera -> body
  int source_index = 0;  // index in the calibration file (stays stable when a subset is taken)
};

class Rig {
 public:
  std::vector<RigCamera> cameras;
  // IMU (or EuRoC body) frame relative to our body frame, when the calibration gives it. Used to
  // bring ground truth expressed for the IMU into our body frame.
  std::optional<SE3> T_b_imu;

  int size() const { return static_cast<int>(cameras.size()); }
  const CameraModel& model(int cam) const { return cameras[cam].model; }
  const SE3& T_b_c(int cam) const { return cameras[cam].T_b_c; }
  // Each camera's centre in the body frame, in camera order: into `out` (as many as it holds), or a new vector.
  void cameraCenters(std::span<Vec3> out) const {
    for (std::size_t c = 0; c < out.size() && c < cameras.size(); ++c) out[c] = cameras[c].T_b_c.t;
  }
  std::vector<Vec3> cameraCenters() const {
    std::vector<Vec3> centers(cameras.size());
    cameraCenters(centers);
    return centers;
  }

  // Bearing in camera `cam` -> Plücker ray in the body frame.
  PluckerRay ray(int cam, const Vec3& bearing_c) const {
    const SE3& T = cameras[cam].T_b_c;
    PluckerRay r;
    r.d = T.R * bearing_c;
    r.m = T.t.cross(r.d);
    return r;
  }

  // The cameras at the given calibration indices, in that order, keeping the body frame of the
  // full rig so that trajectories of different subsets stay comparable. Throws InputError for an
  // index that does not exist or appears twice.
  Rig subset(const std::vector<int>& indices) const;

  // Changes the body frame: new_T_b_c = T_newb_oldb * T_b_c.
  void rebase(const SE3& T_newb_oldb);
};

// "0,2,4" -> {0,2,4}; throws InputError naming the text when it is malformed.
std::vector<int> parseCameraList(const std::string& text);

}  // namespace mcslam
