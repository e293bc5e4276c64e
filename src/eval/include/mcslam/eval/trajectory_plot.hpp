#pragma once
// Top view of a reference and an estimated trajectory as a PNG: the two axes along which the trajectories
// extend most (our world frames are camera-like with y down, so usually x-z), equal aspect, metric grid,
// reference dashed dark grey, estimate coloured by its error with a colour bar, start/end markers, legend.
#include <string>
#include <vector>

#include "mcslam/core/se3.hpp"

namespace mcslam {

struct TrajectoryPlot {
  std::string title;                      // first line, e.g. "APE: rmse 0.0081 m (0.43 % of 18.9 m)"
  std::string subtitle;                   // second line, smaller (settings, file names)
  std::vector<Vec3> reference;            // drawn dashed grey, thin, over the estimate
  std::vector<Vec3> estimate;             // drawn coloured by estimate_error
  std::vector<double> estimate_error;     // one per estimate point (NaN: no value, drawn grey)
  std::string error_label = "error [m]";  // colour bar caption
  std::string reference_label = "reference";
  std::string estimate_label = "estimate";
};

// Throws InputError naming the path when the file cannot be written or there is nothing to draw.
void writeTrajectoryPlot(const std::string& png_path, const TrajectoryPlot& plot, int width = 1400, int height = 1000);

}  // namespace mcslam
