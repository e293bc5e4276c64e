#pragma once
// A map file read whole, into memory sized by the file rather than by a configuration: what tools that inspect
// maps (mcslam-map) need. The SLAM reads maps with PlaceMemory::readMap, into its fixed capacities.
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "mcslam/places/loop_closer.hpp"
#include "mcslam/places/map_file.hpp"
#include "mcslam/places/place_map.hpp"

namespace mcslam {

struct MapContents {
  std::size_t file_bytes = 0;
  MapFileHeader header;
  std::unique_ptr<PlaceMap> map;  // keyframes in slots 0..size()-1
  std::vector<uint32_t> words;    // how many words each keyframe has in the database, by slot
  std::vector<LoopEdge> loops;
  std::vector<int32_t> segment_roots;  // per segment: the segment the loops joined it to
};

// InputError naming `name` and the fault, as for PlaceMemory::readMap, for anything that is not a whole map file.
MapContents readMapContents(std::string_view bytes, const std::string& name);

}  // namespace mcslam
