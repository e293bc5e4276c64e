#include <algorithm>

#include "mcslam/core/error.hpp"
#include "mcslam/dataset/trajectory.hpp"
#include "mcslam/sim/trajectory.hpp"

namespace mcslam::sim {

namespace {

class FileTrajectory : public SimTrajectory {
 public:
  explicit FileTrajectory(const std::string& path) : path_(path), poses_(readTumTrajectory(path)) {
    if (poses_.size() < 2)
      throw InputError(path + ": a trajectory needs at least 2 poses, has " + std::to_string(poses_.size()));
    for (std::size_t i = 1; i < poses_.size(); ++i) {
      if (poses_[i].t <= poses_[i - 1].t) {
        throw InputError(path + ": pose " + std::to_string(i + 1) + " is not later than the one before");
      }
    }
  }
  double duration() const override { return toSeconds(poses_.back().t - poses_.front().t); }
  Timestamp startStamp() const override { return poses_.front().t; }
  std::string description() const override { return "file " + path_; }

  SE3 bodyPose(double t, const SE3&) const override {
    const Timestamp ts = poses_.front().t + fromSeconds(std::clamp(t, 0.0, duration()));
    auto it =
        std::lower_bound(poses_.begin(), poses_.end(), ts, [](const StampedPose& p, Timestamp v) { return p.t < v; });
    if (it == poses_.begin()) return poses_.front().T_w_b;
    if (it == poses_.end()) return poses_.back().T_w_b;
    const StampedPose& b = *it;
    const StampedPose& a = *(it - 1);
    const double f = static_cast<double>(ts - a.t) / static_cast<double>(b.t - a.t);
    const Eigen::Quaterniond q = a.T_w_b.quaternion().slerp(f, b.T_w_b.quaternion());
    return SE3(q, (1 - f) * a.T_w_b.t + f * b.T_w_b.t);
  }

 private:
  std::string path_;
  Trajectory poses_;
};

}  // namespace

std::shared_ptr<const SimTrajectory> makeFileTrajectory(const std::string& tum_path) {
  return std::make_shared<FileTrajectory>(tum_path);
}

std::vector<std::string> trajectoryNames() { return {"ground", "handheld", "file:PATH"}; }

std::string describeTrajectories() {
  return "  ground     ground robot on the world's loop: ~1 m/s, corners at up to ~50 deg/s, 2 s stops, bumps;\n"
         "             rig centre 1.0 m above the floor; ends where it started\n"
         "  handheld   person walking the loop, rig at 1.45 m: smooth 6-DoF motion (bob, sway, look-around)\n"
         "  file:PATH  follow a TUM trajectory of the rig body (world z up), interpolated; keeps its time stamps\n";
}

std::shared_ptr<const SimTrajectory> makeTrajectory(const std::string& spec, const World& world, uint64_t seed) {
  if (spec == "ground") return makeGroundTrajectory(world, seed);
  if (spec == "handheld") return makeHandheldTrajectory(world, seed);
  if (spec.rfind("file:", 0) == 0) {
    if (spec.size() == 5) throw InputError("trajectory 'file:' needs a path (file:PATH)");
    return makeFileTrajectory(spec.substr(5));
  }
  throw InputError("unknown trajectory '" + spec + "' (trajectories: ground, handheld, file:PATH)");
}

double yawRateDeg(const SimTrajectory& traj, const SE3& T_v_b, double t, double dt) {
  auto yaw = [&](double tt) {
    const SE3 T_w_v = traj.bodyPose(tt, T_v_b) * T_v_b.inverse();
    const Vec3 fwd = T_w_v.R.col(0);
    return std::atan2(fwd.y(), fwd.x());
  };
  double d = yaw(t + dt) - yaw(t - dt);
  while (d > M_PI) d -= 2 * M_PI;
  while (d < -M_PI) d += 2 * M_PI;
  return d / (2 * dt) * 180 / M_PI;
}

}  // namespace mcslam::sim
