#pragma once
// Rendered rig frames for front-end tests: one Simulation per (rig, world) per process, built on first
// use (world construction takes seconds), and frames rendered with their depth along the optical axis.
#include <functional>
#include <string>
#include <vector>

#include "mcslam/core/image.hpp"
#include "mcslam/pipeline/frame_processor.hpp"
#include "mcslam/pipeline/pipeline_config.hpp"
#include "mcslam/sim/simulation.hpp"

namespace mcslam::test {

// The shared simulation of a preset rig in a world (seed 1, ground trajectory, 10 Hz).
sim::Simulation& sharedSimulation(const std::string& rig, const std::string& world);

// One rig frame: images and depth of the rendered cameras (the others stay empty).
struct RenderedFrame {
  std::vector<Image> images;
  std::vector<sim::DepthImage> depths;
  std::vector<ImageView> views;
  std::unique_ptr<bool[]> present;

  RigFrameView view() const;
};

// Renders `cameras` of frame `frame` (depth included).
RenderedFrame renderFrame(sim::Simulation& sim, int frame, const std::vector<int>& cameras);

// Depth along camera's optical axis at the pixel nearest (x, y); 0 outside or where nothing was hit.
double depthAt(const sim::DepthImage& depth, double x, double y);

// Truth at a keypoint (x, y, octave) for a depth estimate: the depth at its pixel, or on a depth discontinuity
// the depth within the keypoint's rounding nearest to the estimate (*edge tells which; sim_frames.cpp says why).
double trueDepth(const sim::DepthImage& depth, double x, double y, int octave, double estimate, bool* edge = nullptr);

// The front-end of `config` on the front cameras 0-4 of frame `frame`: each multi-view feature with a point whose
// relative depth sigma is at most `max_sigma`, where something was rendered, with the relative error of its depth
// (along its reference camera's axis) against the rendered one, and whether that truth lies on a discontinuity.
void forEachFrontCameraDepth(sim::Simulation& sim, const PipelineConfig& config, int frame, double max_sigma,
                             const std::function<void(const MultiViewFeature& mv, double error, bool edge)>& visit);

}  // namespace mcslam::test
