#pragma once
// One line per pose, shared by mcslam-shm-echo and mcslam-udp-echo (so a test can compare them).
#include <cstdio>

#include "mcslam/pose_protocol.hpp"

namespace mcslam::tools {

// "seq 12 frame 12 t 1403636579.763555584 state tracking valid 1 kf 0 unscaled 0 unanchored 0 world 3 quality 0.830
// p 0.1 -0.2 0.3 q 0 0 0 1" (one line). Numbers with %.17g so they read back to the same doubles.
inline void printPose(const pose::PoseRecord& r, std::FILE* out) {
  const long long t = r.capture_time_ns;
  std::fprintf(
      out,
      "seq %llu frame %llu t %lld.%09lld state %s valid %d kf %d unscaled %d unanchored %d world %u quality %.3f "
      "p %.17g %.17g %.17g q %.17g %.17g %.17g %.17g\n",
      static_cast<unsigned long long>(r.sequence), static_cast<unsigned long long>(r.frame_sequence), t / 1000000000,
      (t < 0 ? -t : t) % 1000000000, pose::trackingName(r.tracking), r.valid() ? 1 : 0, r.keyframe() ? 1 : 0,
      r.unscaled() ? 1 : 0, r.unanchored() ? 1 : 0, static_cast<unsigned>(r.world_revision),
      static_cast<double>(r.quality), r.position[0], r.position[1], r.position[2], r.orientation[0], r.orientation[1],
      r.orientation[2], r.orientation[3]);
  std::fflush(out);
}

}  // namespace mcslam::tools
