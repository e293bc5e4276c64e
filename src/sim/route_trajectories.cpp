// Ground-robot and hand-held trajectories along a world's route. Every wobble is a periodic function of the arc
// length with a whole number of cycles per loop, so the loop closes exactly in all six degrees of freedom.
#include <algorithm>
#include <cmath>

#include "arc_timing.hpp"
#include "hash.hpp"
#include "mcslam/sim/trajectory.hpp"
#include "route_curve.hpp"

namespace mcslam::sim {

namespace {

Mat3 rpy(double yaw, double pitch, double roll) {
  return (Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
          Eigen::AngleAxisd(roll, Vec3::UnitX()))
      .toRotationMatrix();
}

// Sum of sines in s with whole cycles over the loop: periodic wobble with about the given wavelengths.
class LoopWobble {
 public:
  LoopWobble() = default;
  LoopWobble(Rng& rng, double length, const std::vector<double>& wavelengths, const std::vector<double>& amplitudes)
      : length_(length) {
    for (std::size_t k = 0; k < wavelengths.size(); ++k) {
      const double cycles = std::max(1.0, std::round(length / wavelengths[k]));
      terms_.push_back({cycles, amplitudes[k], rng.uniform(0, 2 * M_PI)});
    }
  }
  double operator()(double s) const {
    double v = 0;
    for (const Term& t : terms_) v += t.amplitude * std::sin(2 * M_PI * t.cycles * s / length_ + t.phase);
    return v;
  }

 private:
  struct Term {
    double cycles, amplitude, phase;
  };
  double length_ = 1;
  std::vector<Term> terms_;
};

class GroundTrajectory : public PlatformTrajectory {
 public:
  GroundTrajectory(const World& world, uint64_t seed, const GroundOptions& o) : curve_(world.route()), options_(o) {
    checkRouteClearance(world, curve_, world.route().clearance);
    SpeedLimits lim;
    lim.cruise = o.cruise_speed;
    lim.max_yaw_rate = o.max_yaw_rate_deg * M_PI / 180;
    lim.lateral_accel = o.lateral_accel;
    lim.accel = o.accel;
    timing_ = std::make_unique<ArcTiming>(curve_, lim, curve_.stops(), o.stop_seconds);
    Rng rng(hashOf(seed, 0x9a0d));
    const double L = curve_.length();
    const double mm = 0.001, deg = M_PI / 180;
    z_ = LoopWobble(rng, L, {0.31, 0.77, 1.9}, {0.6 * mm, 0.8 * mm, 1.2 * mm});
    pitch_ = LoopWobble(rng, L, {0.43, 1.3}, {0.12 * deg, 0.15 * deg});
    roll_ = LoopWobble(rng, L, {0.37, 1.1}, {0.1 * deg, 0.15 * deg});
    // Door thresholds and cable covers: short bumps on straight stretches, away from the start.
    for (int tries = 0; tries < 400 && bumps_.size() < 4; ++tries) {
      const double s = rng.uniform(0.1 * L, 0.9 * L);
      Vec2 p;
      double h, k;
      curve_.at(s, p, h, k);
      bool far = std::abs(k) < 0.05;
      for (double b : bumps_) far = far && std::abs(b - s) > 5.0;
      if (far) bumps_.push_back(s);
    }
  }

  double duration() const override { return timing_->duration(); }
  std::string description() const override { return "ground robot, loop of " + std::to_string(curve_.length()) + " m"; }

  SE3 platformPose(double t) const override {
    const double s = timing_->arcAt(std::clamp(t, 0.0, duration()));
    Vec2 p;
    double heading, kappa;
    curve_.at(s, p, heading, kappa);
    double z = options_.height, pitch = 0, roll = 0;
    if (options_.bumps) {
      z += z_(s);
      pitch += pitch_(s);
      roll += roll_(s);
      for (double b : bumps_) {  // 12 mm high, about 0.3 m long; nose up while climbing
        const double u = (s - b) / 0.12, g = std::exp(-u * u);
        z += 0.012 * g;
        pitch -= std::atan(0.6 * 0.012 * g * (-2 * u / 0.12));
      }
    }
    return SE3(rpy(heading, pitch, roll), Vec3(p.x(), p.y(), z));
  }

 private:
  RouteCurve curve_;
  GroundOptions options_;
  std::unique_ptr<ArcTiming> timing_;
  LoopWobble z_, pitch_, roll_;
  std::vector<double> bumps_;
};

class HandheldTrajectory : public PlatformTrajectory {
 public:
  HandheldTrajectory(const World& world, uint64_t seed, const HandheldOptions& o) : curve_(world.route()), options_(o) {
    checkRouteClearance(world, curve_, world.route().clearance);
    SpeedLimits lim;
    lim.cruise = o.speed;
    lim.max_yaw_rate = 70 * M_PI / 180;
    lim.lateral_accel = 0.6;
    lim.accel = 0.4;
    timing_ = std::make_unique<ArcTiming>(curve_, lim, std::vector<double>{}, 0.0);
    Rng rng(hashOf(seed, 0x4a7d));
    const double L = curve_.length(), deg = M_PI / 180, step = 0.7;
    bob_ = LoopWobble(rng, L, {step}, {0.015});
    sway_ = LoopWobble(rng, L, {2 * step, 9.0}, {0.03, 0.04});
    yaw_ = LoopWobble(rng, L, {11.0, 23.0, 4.1}, {9 * deg, 7 * deg, 2 * deg});
    pitch_ = LoopWobble(rng, L, {7.0, 2 * step, 0.9}, {4 * deg, 0.8 * deg, 0.4 * deg});
    roll_ = LoopWobble(rng, L, {13.0, 2 * step}, {2.5 * deg, 0.8 * deg});
  }

  double duration() const override { return timing_->duration(); }
  std::string description() const override { return "hand-held, loop of " + std::to_string(curve_.length()) + " m"; }

  SE3 platformPose(double t) const override {
    const double s = timing_->arcAt(std::clamp(t, 0.0, duration()));
    Vec2 p;
    double heading, kappa;
    curve_.at(s, p, heading, kappa);
    const Vec2 left(-std::sin(heading), std::cos(heading));
    const Vec2 q = p + sway_(s) * left;
    return SE3(rpy(heading + yaw_(s), pitch_(s) - 3 * M_PI / 180, roll_(s)),
               Vec3(q.x(), q.y(), options_.height + bob_(s)));
  }

 private:
  RouteCurve curve_;
  HandheldOptions options_;
  std::unique_ptr<ArcTiming> timing_;
  LoopWobble bob_, sway_, yaw_, pitch_, roll_;
};

}  // namespace

std::shared_ptr<const PlatformTrajectory> makeGroundTrajectory(const World& world, uint64_t seed,
                                                               const GroundOptions& options) {
  return std::make_shared<GroundTrajectory>(world, seed, options);
}

std::shared_ptr<const PlatformTrajectory> makeHandheldTrajectory(const World& world, uint64_t seed,
                                                                 const HandheldOptions& options) {
  return std::make_shared<HandheldTrajectory>(world, seed, options);
}

}  // namespace mcslam::sim
