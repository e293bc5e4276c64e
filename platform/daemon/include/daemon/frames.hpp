#pragma once
// The slots that travel through the daemon's rings after the assembly (camera images before it:
// sources/camera_frame.hpp), and the typed rings that carry them. All image buffers are sized at start-up;
// moving a frame from one stage to the next swaps buffers instead of copying or allocating.
#include <cstdint>
#include <memory>
#include <vector>

#include "mcslam/core/image.hpp"
#include "mcslam/pipeline/frame_processor.hpp"
#include "realtime/signalled_ring.hpp"

namespace mcslam::platform {

// A synchronized capture of the whole rig (assembly -> processing).
struct RigFrame {
  std::vector<Image> images;        // one per camera, each sized for its camera
  std::unique_ptr<bool[]> present;  // which cameras contributed
  Timestamp capture_ns = 0;         // stamp of the first image that arrived (the matching key)
  uint64_t sequence = 0;            // trigger index of the rig frame
  int64_t trigger_mono_ns = 0;
  int cameras = 0;

  void allocate(const std::vector<std::pair<int, int>>& sizes) {
    cameras = static_cast<int>(sizes.size());
    images.resize(sizes.size());
    for (std::size_t c = 0; c < sizes.size(); ++c) images[c].resize(sizes[c].first, sizes[c].second);
    present.reset(new bool[sizes.size()]());
  }
  int presentCount() const {
    int n = 0;
    for (int c = 0; c < cameras; ++c) n += present[c] ? 1 : 0;
    return n;
  }
};

// A processed frame (processing -> publishing).
struct PoseSlot {
  PoseEstimate estimate;
  int64_t trigger_mono_ns = 0;
  int cameras_present = 0;
};

using RigRing = SignalledRing<RigFrame>;   // assembly -> processing
using PoseRing = SignalledRing<PoseSlot>;  // processing -> publishing

}  // namespace mcslam::platform
