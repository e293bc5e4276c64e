#pragma once
// A contact sheet: one frame of several cameras, downscaled, in a grid, each labelled with its camera index,
// so a rig designer sees what the rig sees in one picture.
#include <string>
#include <vector>

#include "mcslam/core/image.hpp"

namespace mcslam::sim {

struct SheetTile {
  const Image* image = nullptr;
  std::string label;  // drawn in the tile's top-left corner
};

// Tiles scaled by `scale`, up to `columns` per row, 4 px gaps; writes a grey PNG. Throws InputError naming the
// file when it cannot be written.
void writeContactSheet(const std::string& path, const std::vector<SheetTile>& tiles, double scale, int columns = 4);

}  // namespace mcslam::sim
