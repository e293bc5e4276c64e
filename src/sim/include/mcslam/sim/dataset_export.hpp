#pragma once
// Writes a Simulation as a dataset in the native ASL layout (mcslam::AslDatasetWriter):
//   DIR/camchain.yaml             the written cameras, body frame = the first written camera
//   DIR/camN/data.csv, data/<ns>.png   8-bit grey images
//   DIR/camN/depth/<ns>.png       16-bit depth along the optical axis in millimetres (0 = no surface or beyond
//                                 65.535 m), same stamps as the images
//   DIR/groundtruth.txt           TUM poses of the body (the first written camera) in the world (z up)
//   DIR/sim.yaml                  how it was made (rig, world, trajectory, seed, rate, path length)
#include <functional>
#include <string>
#include <vector>

#include "mcslam/sim/simulation.hpp"

namespace mcslam::sim {

struct ExportOptions {
  std::vector<int> cameras;  // calibration indices to write; empty = all
  bool depth = true;
  std::string description;                            // free text recorded in sim.yaml
  std::function<void(int done, int total)> progress;  // called after each frame
};

struct ExportSummary {
  int frames = 0;
  int cameras = 0;
  double path_length = 0;  // metres travelled by the body
  double duration = 0;     // seconds between the first and last frame
};

// Throws InputError when the folder cannot be written or a camera index does not exist.
ExportSummary exportDataset(Simulation& sim, const std::string& dir, const ExportOptions& options = {});

// Depth image -> 16-bit millimetres as written by exportDataset.
void writeDepthPng(const std::string& path, const DepthImage& depth);

}  // namespace mcslam::sim
