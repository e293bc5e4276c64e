#include "mcslam/odometry/loss_clock.hpp"

namespace mcslam {

bool LossClock::frame(Timestamp t) {
  const bool increasing = !has_last_ || t > last_;
  if (has_last_) {
    if (increasing)
      lost_ns_ += t - last_;
    else
      ++not_increasing_;
  }
  has_last_ = true;
  last_ = t;
  return increasing;
}

}  // namespace mcslam
