#pragma once
// The top view of a place map (mcslam-map info --plot): its points as a grey density, each odometry segment's
// keyframes as a path in a colour of its own, and the loops that joined keyframes as red links. Coordinates are
// those of the plane drawn (the caller projects).
#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

namespace mcslam {

struct MapPlot {
  std::string title;     // first line
  std::string subtitle;  // second line, smaller
  std::string h_caption = "[m]", v_caption = "[m]";
  std::vector<Eigen::Vector2d> points;
  struct Path {
    std::string label;
    std::vector<Eigen::Vector2d> keyframes;
  };
  std::vector<Path> paths;
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> loops;
};

// Throws InputError naming the path when the file cannot be written or the map has no keyframe.
void writeMapPlot(const std::string& png_path, const MapPlot& plot, int width = 1400, int height = 1000);

}  // namespace mcslam
