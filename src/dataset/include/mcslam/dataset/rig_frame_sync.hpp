#pragma once
// Assembling images of several cameras into rig frames by timestamp.
//
// All stamps are merged in time order; a frame opens at its earliest stamp and takes the following stamps
// that lie within the tolerance of it, at most one per camera. A camera without an image near that time is
// absent from the frame (never paired with a neighbouring frame's image), and a second stamp of a camera
// always opens a new frame.
#include <string>
#include <vector>

#include "mcslam/core/time.hpp"
#include "mcslam/dataset/dataset.hpp"

namespace mcslam {

struct CameraImage {
  Timestamp t = 0;
  std::string path;
};

// per_camera[c] must be sorted by time with unique stamps. Frames come out sorted by time.
std::vector<RigFrameEntry> assembleRigFrames(const std::vector<std::vector<CameraImage>>& per_camera,
                                             Timestamp tolerance_ns);

// A third of the shortest per-camera median frame period, at most max_ns (when no camera has two images: 5 ms, or
// max_ns if less).
Timestamp automaticSyncTolerance(const std::vector<std::vector<CameraImage>>& per_camera, Timestamp max_ns = 5000000);

}  // namespace mcslam
