#pragma once
// Small synthetic rigs and scenes for front-end tests (no rendering): points in front of the rig
// projected exactly into every camera that sees them.
#include <random>
#include <vector>

#include "mcslam/calib/rig.hpp"

namespace mcslam::test {

// Eight pinhole cameras around the body's vertical (y) axis, 45 degrees apart, 0.2 m from the centre.
Rig ring8Rig(double hfov_deg = 70.0);
// The paper's five front cameras (tests/data/calib/isec_5cam_camchain.yaml).
Rig isecRig();

// A point seen by the rig: its body-frame position and its pixel in each camera (when visible).
struct ScenePoint {
  Vec3 p_b;
  std::vector<bool> visible;
  std::vector<Vec2> uv;
};

// Random points in front of the rig at depths [min_depth, max_depth] (uniform in inverse depth).
std::vector<ScenePoint> randomScene(const Rig& rig, int count, double min_depth, double max_depth, std::mt19937& rng);

}  // namespace mcslam::test
