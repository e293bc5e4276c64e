#pragma once
// The top view of a map (`mcslam-map info --plot`): the plane it is drawn in and the drawing.
#include <string>

#include "mcslam/core/se3.hpp"
#include "mcslam/places/map_contents.hpp"

namespace mcslam::map_tool {

// The plane seen from above: `h` right, `v` up, `up` towards the viewer (h x v = up).
struct TopView {
  Vec3 h = Vec3::UnitX(), v = Vec3::UnitY(), up = Vec3::UnitZ();
  std::string how;  // how the plane was chosen, for the plot's subtitle
};

// The plane the keyframes moved in (a robot on a floor), its normal towards up: against the first keyframe's y axis
// (down in a camera's frame, which a rig's body frame usually is). A path that does not span a plane (a straight
// road, a hand-held rig turning on the spot) is seen along that up. `h` follows the path's main direction.
TopView topViewOf(const PlaceMap& map);

void plotMap(const MapContents& contents, const std::string& file, const std::string& png);

}  // namespace mcslam::map_tool
