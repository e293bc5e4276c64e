#pragma once
// The window's unit held by all its keyframes (SolverOptions::hold_window_scale): one stiff residual on the log
// of the summed distances from the oldest keyframe (the anchor, held) of those between it and the newest (the
// newest is the tracked one: its distance is what the solve is to find).
#include <cmath>
#include <vector>

#include "window_term.hpp"

namespace mcslam::backend {

class WindowScaleHold final : public WindowTerm {
 public:
  explicit WindowScaleHold(int max_keyframes)
      : held_slots_(static_cast<size_t>(max_keyframes)), J_(static_cast<size_t>(max_keyframes)) {}

  // Takes the reference distance at the window's state; with fewer than three keyframes (or no distance) the
  // term stays off and the caller holds the two oldest keyframes instead.
  void prepare(const WindowStorage& window, bool hold);
  bool active() const { return active_; }

  void linearize(const WindowVariables& v) override;
  void addCost(const WindowVariables& v, bool trial, double& cost) const override;
  void addToSystem(const WindowVariables& v, CameraSystem& system) const override;

 private:
  static constexpr double kSigma = 1e-4;  // of log(summed distances): stiff
  // Summed distances of the held keyframes from the anchor (trial poses or the window's).
  double heldDistance(const WindowStorage& window, const SE3* kf_trial) const;
  double residual(double held_distance) const { return (std::log(held_distance) - log_reference_) / kSigma; }

  bool active_ = false;
  int anchor_ = -1;              // keyframe slot
  std::vector<int> held_slots_;  // the first num_held_
  int num_held_ = 0;
  double log_reference_ = 0;
  double r_ = 0;
  std::vector<Vec6> J_;  // per held slot (index into held_slots_): translation part only
};

}  // namespace mcslam::backend
