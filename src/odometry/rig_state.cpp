#include "mcslam/odometry/rig_state.hpp"

namespace mcslam {

RigState::RigState(const Rig& calibration)
    : rig_(calibration),
      reestimated_(calibration.size(), 0),
      scale_(calibration.size() == 1 ? ScaleStatus::Monocular : ScaleStatus::Metric) {}

void RigState::setExtrinsic(int cam, const SE3& T_b_c) {
  SE3& current = rig_.cameras[cam].T_b_c;
  if (current.R == T_b_c.R && current.t == T_b_c.t) return;
  current = T_b_c;
  ++version_;
}

void RigState::markReestimated(int cam) {
  if (reestimated_[cam]) return;
  reestimated_[cam] = 1;
  ++version_;
}

void RigState::setScale(ScaleStatus s) {
  if (scale_ == s) return;
  scale_ = s;
  ++version_;
}

}  // namespace mcslam
