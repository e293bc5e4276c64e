#pragma once
// `mcslam-rig overlap`: the overlap map of a rig as text, JSON and pictures of the cells.
#include <string>

#include "mcslam/features/overlap_map.hpp"

namespace mcslam::rigtool {

void printOverlapText(const Rig& rig, const OverlapMap& map);
void printOverlapJson(const Rig& rig, const OverlapMap& map);
// One PNG per ordered overlapping pair in `dir`: camera i's cells that see into camera j (left), camera j's
// cells reachable from them (right), and for one example cell of i its candidate cells in j.
// Returns the number of files written.
int writeOverlapPngs(const Rig& rig, const OverlapMap& map, const std::string& dir);

}  // namespace mcslam::rigtool
