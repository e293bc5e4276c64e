#pragma once
// Pinhole camera with radial-tangential (Kalibr "radtan", OpenCV plumb-bob with 4 coefficients) or
// equidistant (Kalibr "equidistant", OpenCV fisheye) distortion, or none.
//
// Pixel convention (Kalibr/OpenCV): u = fx * x_d + cx, the centre of pixel (0,0) is at (0,0).
// Unprojection returns a unit bearing vector, so fisheye pixels beyond 90 degrees are represented.
// Both directions are valid only inside the domain where the distortion is monotonic, so a point
// far outside the field of view never folds back into the image.
#include <array>
#include <string>

#include "mcslam/core/se3.hpp"

namespace mcslam {

enum class Distortion { None, RadTan, Equidistant };

const char* distortionName(Distortion d);  // "none", "radtan", "equidistant"

class CameraModel {
 public:
  CameraModel() = default;
  // coeffs: radtan k1 k2 p1 p2; equidistant k1 k2 k3 k4; ignored for None.
  CameraModel(int width, int height, double fx, double fy, double cx, double cy, Distortion distortion,
              const std::array<double, 4>& coeffs = {0, 0, 0, 0});

  int width() const { return width_; }
  int height() const { return height_; }
  Distortion distortion() const { return distortion_; }
  double fx() const { return fx_; }
  double fy() const { return fy_; }
  double cx() const { return cx_; }
  double cy() const { return cy_; }
  const std::array<double, 4>& coeffs() const { return k_; }

  // Point in the camera frame -> pixel. False when the point is behind the camera or outside the
  // model's valid domain (the pixel is then unspecified). J (optional) = d(uv)/d(p).
  bool project(const Vec3& p, Vec2& uv, Mat23* J = nullptr) const;

  // Pixel -> unit bearing vector in the camera frame. False outside the valid domain.
  bool unproject(const Vec2& uv, Vec3& bearing) const;

  // Pixel lies inside the image, at least `border` pixels from the edge.
  bool inImage(const Vec2& uv, double border = 0.0) const {
    return uv.x() >= border && uv.y() >= border && uv.x() <= width_ - 1 - border && uv.y() <= height_ - 1 - border;
  }

  // Largest angle from the optical axis that projects validly, radians.
  double maxValidAngle() const { return max_angle_; }
  // Widest angle from the optical axis that a pixel of the image sees, radians: the maximum over the image border
  // (where it lies for any lens whose radial mapping grows outwards), sampled every 4 pixels; pi when a border
  // pixel has no bearing. No point outside this cone projects into the image.
  double imageHalfAngle() const;

  // Distortion applied to a point on the normalised plane (radtan) or to the unit-plane
  // direction scaled by the angle (equidistant); exposed for tests and the simulator.
  Vec2 distortNormalized(const Vec2& xy, Mat2* J = nullptr) const;

 private:
  void computeValidDomain();

  int width_ = 0, height_ = 0;
  double fx_ = 1, fy_ = 1, cx_ = 0, cy_ = 0;
  Distortion distortion_ = Distortion::None;
  std::array<double, 4> k_{0, 0, 0, 0};
  double max_angle_ = 0;    // radians from the optical axis
  double max_radius2_ = 0;  // radtan/none: largest squared radius on the normalised plane
};

}  // namespace mcslam
