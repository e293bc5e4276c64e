#include "mcslam/sim/simulation.hpp"

#include <cmath>

#include "mcslam/core/error.hpp"
#include "mcslam/sim/rig_presets.hpp"

namespace mcslam::sim {

namespace {
RenderOptions seeded(RenderOptions r, uint64_t seed) {
  r.seed = seed;
  return r;
}
}  // namespace

Simulation::Simulation(const SimulationConfig& c) {
  if (!(c.rate_hz > 0) || !std::isfinite(c.rate_hz)) {
    throw InputError("rate must be a positive number of frames per second, got " + std::to_string(c.rate_hz));
  }
  if (c.frames < 0) throw InputError("frames must not be negative, got " + std::to_string(c.frames));
  rig_ = loadRig(c.rig);
  WorldOptions wo;
  wo.seed = c.seed;
  wo.moving_objects = c.moving_objects;
  wo.textures_dir = c.textures_dir;
  world_ = makeWorld(c.world, wo);
  trajectory_ = makeTrajectory(c.trajectory, *world_, c.seed);
  rate_ = c.rate_hz;
  renderer_ = std::make_unique<Renderer>(world_, rig_, seeded(c.render, c.seed));
  init(c.frames);
}

Simulation::Simulation(Rig rig, std::shared_ptr<const World> world, std::shared_ptr<const SimTrajectory> trajectory,
                       double rate_hz, int frames, const RenderOptions& render)
    : rig_(std::move(rig)), world_(std::move(world)), trajectory_(std::move(trajectory)), rate_(rate_hz) {
  if (!(rate_hz > 0)) throw InputError("rate must be positive, got " + std::to_string(rate_hz));
  renderer_ = std::make_unique<Renderer>(world_, rig_, render);
  init(frames);
}

void Simulation::init(int frames) {
  if (rig_.size() == 0) throw InputError("the rig has no camera");
  T_v_b_ = rigMount(rig_);
  frames_ = frames > 0 ? frames : static_cast<int>(std::floor(trajectory_->duration() * rate_ + 1e-9)) + 1;
}

Timestamp Simulation::frameStamp(int i) const {
  return trajectory_->startStamp() + static_cast<Timestamp>(std::llround(i * 1e9 / rate_));
}

double Simulation::frameTime(int i) const { return toSeconds(frameStamp(i) - trajectory_->startStamp()); }

SE3 Simulation::bodyPoseAt(double t) const { return trajectory_->bodyPose(t, T_v_b_); }

SE3 Simulation::bodyPose(int i) const { return bodyPoseAt(frameTime(i)); }

Trajectory Simulation::groundTruth() const {
  Trajectory gt;
  gt.reserve(frames_);
  for (int i = 0; i < frames_; ++i) gt.push_back({frameStamp(i), bodyPose(i)});
  return gt;
}

void Simulation::render(int frame, int cam, Image& image, DepthImage* depth) {
  const double t = frameTime(frame);
  if (renderer_->options().sensor.motion_blur_s > 0) {
    renderer_->render(
        cam, [this](double tt) { return bodyPoseAt(tt); }, t, static_cast<uint64_t>(frame), image, depth);
  } else {
    renderer_->render(cam, bodyPoseAt(t), t, static_cast<uint64_t>(frame), image, depth);
  }
}

}  // namespace mcslam::sim
