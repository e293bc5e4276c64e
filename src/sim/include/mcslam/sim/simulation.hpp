#pragma once
// A ready-to-render sequence: rig + world + trajectory + frame rate. What other modules' tests use to get
// images in memory, with exact ground truth, without writing files:
//
//   mcslam::sim::SimulationConfig cfg;            // isec rig, indoor world, ground robot, 10 Hz
//   cfg.frames = 50;
//   mcslam::sim::Simulation sim(cfg);
//   mcslam::Image img;
//   mcslam::sim::DepthImage depth;
//   sim.render(/*frame*/ 0, /*cam*/ 2, img, &depth);
//   mcslam::SE3 T_w_b = sim.bodyPose(0);            // body = the rig's body frame (cam0 for presets)
//
// Frame i is taken at stamp startStamp + round(i * 1e9 / rate) ns; all cameras are triggered together.
#include <memory>
#include <string>

#include "mcslam/calib/rig.hpp"
#include "mcslam/dataset/trajectory.hpp"
#include "mcslam/sim/renderer.hpp"
#include "mcslam/sim/trajectory.hpp"
#include "mcslam/sim/world.hpp"

namespace mcslam::sim {

struct SimulationConfig {
  std::string rig = "isec";           // preset (isec, stereo, mono, ring8) or Kalibr camchain file
  std::string world = "indoor";       // indoor, corridor, courtyard
  std::string trajectory = "ground";  // ground, handheld, file:PATH
  double rate_hz = 10.0;
  int frames = 0;     // 0: as many as the trajectory lasts
  uint64_t seed = 1;  // world layout and textures, trajectory wobble, sensor noise
  bool moving_objects = false;
  std::string textures_dir;  // photographs instead of procedural textures
  RenderOptions render;      // its seed is replaced by `seed`
};

class Simulation {
 public:
  // Throws InputError for an unknown preset/world/trajectory, an unreadable file or a bad rate.
  explicit Simulation(const SimulationConfig& config);
  Simulation(Rig rig, std::shared_ptr<const World> world, std::shared_ptr<const SimTrajectory> trajectory,
             double rate_hz, int frames = 0, const RenderOptions& render = {});

  const Rig& rig() const { return rig_; }
  const World& world() const { return *world_; }
  const std::shared_ptr<const World>& worldPtr() const { return world_; }
  const SimTrajectory& trajectory() const { return *trajectory_; }
  const SE3& mount() const { return T_v_b_; }  // rig body in the platform frame
  double rate() const { return rate_; }

  int frameCount() const { return frames_; }
  Timestamp frameStamp(int i) const;
  double frameTime(int i) const;  // seconds since the trajectory start
  SE3 bodyPose(int i) const;      // T_w_b at frame i
  SE3 bodyPoseAt(double t) const;
  SE3 cameraPose(int i, int cam) const { return bodyPose(i) * rig_.T_b_c(cam); }  // T_w_c
  // Body poses of every frame (TUM stamps), i.e. what groundtruth.txt holds for the full rig.
  Trajectory groundTruth() const;

  // Renders camera `cam` of frame `frame` into caller-owned buffers (resized to the camera's resolution).
  void render(int frame, int cam, Image& image, DepthImage* depth = nullptr);
  Renderer& renderer() { return *renderer_; }

 private:
  void init(int frames);

  Rig rig_;
  std::shared_ptr<const World> world_;
  std::shared_ptr<const SimTrajectory> trajectory_;
  double rate_ = 10.0;
  int frames_ = 0;
  SE3 T_v_b_;
  std::unique_ptr<Renderer> renderer_;
};

}  // namespace mcslam::sim
