#pragma once
// What the absolute-pose stages (RANSAC, refinement) share: a 2D-3D correspondence of the rig and
// the projection of a world point through a camera of the rig, with its analytic Jacobian.
#include <cstdint>
#include <vector>

#include "mcslam/geometry/generalized_p3p.hpp"

namespace mcslam {

// A keypoint of the current rig frame matched to a map point.
struct PoseObservation {
  int camera = 0;             // index of the camera in the rig
  Vec2 pixel = Vec2::Zero();  // measured keypoint, pixels
  BodyRay ray;  // its ray in the body frame: bodyRay(rig, camera, unproject(pixel)), consistent with pixel
  Vec3 point_w = Vec3::Zero();  // the matched map point, world frame
  double sigma_px = 1.0;        // standard deviation of the keypoint (e.g. its pyramid scale), pixels
};

// The observation of keypoint `pixel` of camera `cam` (unit bearing_c = its unprojection, when the
// caller has it already) matched to point_w.
inline PoseObservation makePoseObservation(const Rig& rig, int cam, const Vec2& pixel, const Vec3& bearing_c,
                                           const Vec3& point_w, double sigma_px) {
  return {cam, pixel, bodyRay(rig, cam, bearing_c), point_w, sigma_px};
}
// Same, unprojecting the pixel; false when the pixel is outside the lens's valid domain.
inline bool makePoseObservation(const Rig& rig, int cam, const Vec2& pixel, const Vec3& point_w, double sigma_px,
                                PoseObservation& out) {
  Vec3 bearing_c;
  if (!rig.model(cam).unproject(pixel, bearing_c)) return false;
  out = makePoseObservation(rig, cam, pixel, bearing_c, point_w, sigma_px);
  return true;
}

// The cameras of a rig as the pose solvers need them. Copies the models and extrinsics once (the
// only allocation); projecting allocates nothing.
class RigProjector {
 public:
  RigProjector() = default;
  explicit RigProjector(const Rig& rig);

  int numCameras() const { return static_cast<int>(models_.size()); }
  const CameraModel& model(int cam) const { return models_[cam]; }
  const SE3& T_c_b(int cam) const { return T_c_b_[cam]; }
  // Largest angle one pixel spans anywhere in the image (with a margin): two directions more than
  // n times this apart cannot project closer than n pixels, which lets RANSAC reject a point
  // without the full projection.
  double maxRadiansPerPixel(int cam) const { return max_rad_per_px_[cam]; }
  // A new estimate of camera `cam`'s extrinsic (online calibration).
  void setExtrinsic(int cam, const SE3& T_b_c) { T_c_b_[cam] = T_b_c.inverse(); }

  // Reprojection residual r = project(T_c_b * T_b_w * point_w) - pixel, in pixels. With J, also
  // dr/d(delta) for the body pose perturbed on the right, T_w_b * exp(delta), delta = [rho; phi].
  // False when the point is behind the camera or outside the model's domain (r is then unset),
  // or when the camera index is not in the rig.
  bool residual(const SE3& T_b_w, const PoseObservation& obs, Vec2& r, Mat26* J = nullptr) const;

 private:
  std::vector<CameraModel> models_;
  std::vector<SE3> T_c_b_;
  std::vector<double> max_rad_per_px_;
};

}  // namespace mcslam
