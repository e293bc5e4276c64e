#pragma once
// A known point matched to a keypoint of a frame: what relocalization hands the odometry to start its local map
// from (the points of the place map, in the odometry's frame).
#include <cstdint>

#include "mcslam/core/se3.hpp"
#include "mcslam/features/keypoint.hpp"

namespace mcslam {

struct MapSeed {
  int16_t cam = -1;
  int32_t kp = -1;  // keypoint of that camera in the frame
  Vec3 p_w = Vec3::Zero();
  Descriptor descriptor{};
  bool metric = true;  // its depth is known in metres (a metric map's point)
};

}  // namespace mcslam
