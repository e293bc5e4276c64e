#pragma once
// Four rays at a time: the rays of four neighbouring pixels share the camera centre and the tile's candidates,
// so each candidate is tested against all four with one set of vector operations.
#include <cstdint>
#include <vector>

#include "frame_context.hpp"
#include "simd4.hpp"

namespace mcslam::sim {

struct RayPacket {
  f4 d[3];    // world directions (unit), x, y, z of each lane
  i4 active;  // -1 for real rays, 0 for padding lanes (they hit nothing)
};

// Nearest hits of the packet's rays among `cands` (sorted, sentinel-terminated). `hint` is the index of the
// candidate to try first and becomes the one hit by the first lane that hit. keys[i] = 0 when lane i hits
// nothing (its t is then 0).
void tracePacket(const FrameContext& ctx, const std::vector<Candidate>& cands, const RayPacket& rays, int& hint,
                 uint32_t keys[4], float t[4]);

}  // namespace mcslam::sim
