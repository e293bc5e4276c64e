#pragma once
// Small builders for the evaluator tests.
#include "mcslam/dataset/trajectory.hpp"

namespace mcslam::test {

inline StampedPose pose(double t_s, const Vec3& p, const Mat3& R = Mat3::Identity()) {
  return {fromSeconds(t_s), SE3(R, p)};
}

inline Mat3 rotZ(double rad) { return Eigen::AngleAxisd(rad, Vec3::UnitZ()).toRotationMatrix(); }

}  // namespace mcslam::test
