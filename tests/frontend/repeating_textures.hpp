#pragma once
// Strongly repeating textures (brick walls, tiles, checkerboards, grids, dots, a repeated motif) written as
// PNGs into a folder, for `SimulationConfig::textures_dir`: a rendered world that the front-end was never
// developed on, where a keypoint has lookalikes along its epipolar curve. Each family has its own period, so
// that a figure measured on them does not rest on one spacing.
#include <string>

namespace mcslam::test {

// Writes the textures into `dir` (created if missing) and returns it. Deterministic for a seed.
std::string writeRepeatingTextures(const std::string& dir, unsigned seed = 1);

}  // namespace mcslam::test
