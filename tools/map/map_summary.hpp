#pragma once
// What `mcslam-map info` says of a map file: its rig, segments, size, extent and the capacities it needs.
#include <cstdint>
#include <string>
#include <vector>

#include "mcslam/core/se3.hpp"
#include "mcslam/core/time.hpp"
#include "mcslam/places/map_contents.hpp"

namespace mcslam::map_tool {

struct SegmentSummary {
  int32_t segment = 0;
  int keyframes = 0;
  bool placed = false;
  int32_t joined_to = 0;  // the segment standing for those loops joined it to (itself when none)
  double path_m = 0;      // along its keyframes
  Timestamp t_first = 0, t_last = 0;
};

struct Extent {
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
};

struct MapSummary {
  std::string file;
  std::size_t file_bytes = 0;
  MapFileHeader header;
  int keyframes = 0;
  uint64_t points = 0;     // anchored in keyframes (a landmark seen from several keyframes counts in each)
  uint64_t landmarks = 0;  // distinct odometry landmarks
  uint64_t words = 0;      // database entries
  uint32_t most_words = 0;
  std::vector<uint64_t> points_per_camera;
  std::vector<SegmentSummary> segments;
  int placed_segments = 0;  // in the world frame
  int loop_groups = 0;      // groups of segments joined by loops (a segment no loop joined is one)
  int loops = 0;
  double path_m = 0;
  Extent keyframe_extent;        // keyframe positions in the world
  Extent point_extent;           // points, but for the outermost 2% on each axis
  std::size_t memory_bytes = 0;  // place map and database holding exactly this map
};

MapSummary summarize(const MapContents& contents, const std::string& file);
void printSummary(const MapSummary& s);
void printSummaryJson(const MapSummary& s);

}  // namespace mcslam::map_tool
